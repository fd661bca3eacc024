# The command line with no options gives the library's default mesh.
#
#   TOOL      the stratmesh tool
#   COMPARE   stratmesh_library_default
#   INPUT     the cloud
#   WORK_DIR  emptied and used for the tool's output
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
execute_process(COMMAND "${TOOL}" "${INPUT}" -o "${WORK_DIR}/tool.ply" --quiet
                RESULT_VARIABLE tool_exit)
if(NOT tool_exit EQUAL 0)
  message(FATAL_ERROR "the tool exited with ${tool_exit} on ${INPUT}")
endif()
execute_process(COMMAND "${COMPARE}" "${INPUT}" "${WORK_DIR}/tool.ply" RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  message(FATAL_ERROR "the tool's mesh of ${INPUT} is not the library default's")
endif()
