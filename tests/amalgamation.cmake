# The committed stratmesh.h must be what tools/amalgamate.py writes from src/, and the check
# must be able to fail: on a copy of src/ with one line more, it has to report a difference.
#   cmake -DPYTHON=python3 -DSOURCE_DIR=<repository> -DWORK_DIR=<scratch> -P amalgamation.cmake
execute_process(COMMAND ${PYTHON} ${SOURCE_DIR}/tools/amalgamate.py --check
                RESULT_VARIABLE current)
if(NOT current EQUAL 0)
  message(FATAL_ERROR "stratmesh.h is not what tools/amalgamate.py writes from src/")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
file(COPY ${SOURCE_DIR}/src DESTINATION ${WORK_DIR})
file(APPEND ${WORK_DIR}/src/arena.h "// one line more\n")
execute_process(COMMAND ${PYTHON} ${SOURCE_DIR}/tools/amalgamate.py --check
                        --src ${WORK_DIR}/src --out ${SOURCE_DIR}/stratmesh.h
                RESULT_VARIABLE changed ERROR_QUIET)
if(changed EQUAL 0)
  message(FATAL_ERROR "the control: the check passes a src/ that differs from stratmesh.h")
endif()
message(STATUS "stratmesh.h is current, and the check fails on a changed src/ (control)")
