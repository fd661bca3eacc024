# Runs the stratmesh tool once, in a fresh directory, and checks what it did.
#
#   TOOL           the tool
#   ARGS           its arguments, separated by '|'
#   WORK_DIR       emptied and used as the working directory
#   EXPECT_EXIT    the exit code it must return
#   EXPECT_STDOUT  optional regular expression stdout must match
#   EXPECT_STDERR  optional regular expression stderr must match
#   REJECT_STDERR  optional regular expression stderr must not match
#   STDIN_FILE     optional file given as the tool's standard input
#   STDOUT_FILE    optional file in WORK_DIR that receives the tool's standard output
#                  (EXPECT_STDOUT is then not checked)
#   CHECKS         optional commands to run afterwards in WORK_DIR, each must exit 0:
#                  arguments separated by '|', commands by '||'
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

string(REPLACE "|" ";" args "${ARGS}")
set(streams "")
if(DEFINED STDIN_FILE)
  list(APPEND streams INPUT_FILE "${STDIN_FILE}")
endif()
if(DEFINED STDOUT_FILE)
  list(APPEND streams OUTPUT_FILE "${WORK_DIR}/${STDOUT_FILE}")
else()
  list(APPEND streams OUTPUT_VARIABLE out)
endif()
execute_process(COMMAND "${TOOL}" ${args}
  WORKING_DIRECTORY "${WORK_DIR}"
  RESULT_VARIABLE code ERROR_VARIABLE err ${streams})
message(STATUS "stratmesh ${args}\n-- exit: ${code}\n-- stdout:\n${out}\n-- stderr:\n${err}")

if(NOT "${code}" STREQUAL "${EXPECT_EXIT}")
  message(FATAL_ERROR "exit code ${code}, expected ${EXPECT_EXIT}")
endif()
if(DEFINED EXPECT_STDOUT AND NOT out MATCHES "${EXPECT_STDOUT}")
  message(FATAL_ERROR "stdout does not match '${EXPECT_STDOUT}'")
endif()
if(DEFINED EXPECT_STDERR AND NOT err MATCHES "${EXPECT_STDERR}")
  message(FATAL_ERROR "stderr does not match '${EXPECT_STDERR}'")
endif()

if(DEFINED REJECT_STDERR AND err MATCHES "${REJECT_STDERR}")
  message(FATAL_ERROR "stderr matches '${REJECT_STDERR}'")
endif()

if(DEFINED CHECKS AND NOT CHECKS STREQUAL "")
  string(REPLACE "||" ";" checks "${CHECKS}")
  foreach(check IN LISTS checks)
    string(REPLACE "|" ";" command "${check}")
    execute_process(COMMAND ${command}
      WORKING_DIRECTORY "${WORK_DIR}"
      RESULT_VARIABLE check_code OUTPUT_VARIABLE check_out ERROR_VARIABLE check_err)
    if(NOT check_code EQUAL 0)
      message(FATAL_ERROR "check failed (${check_code}): ${command}\n${check_out}${check_err}")
    endif()
  endforeach()
endif()
