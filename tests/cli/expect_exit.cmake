# Runs COMMAND and checks its exit code and that its output contains EXPECT_OUTPUT, within TIMEOUT seconds
# (120 unless given). An EXPECT_OUTPUT that starts with "regex:" is a CMake regular expression the output
# must match instead (to tie a verdict to its table row, say).
if(NOT DEFINED TIMEOUT)
  set(TIMEOUT 120)
endif()
execute_process(COMMAND ${COMMAND} WORKING_DIRECTORY ${WORKDIR} RESULT_VARIABLE code OUTPUT_VARIABLE out
                ERROR_VARIABLE err TIMEOUT ${TIMEOUT})
if(EXPECT_OUTPUT MATCHES "^regex:(.*)$")
  string(REGEX MATCH "${CMAKE_MATCH_1}" match "${out}${err}")
  set(found -1)
  if(match)
    set(found 0)
  endif()
else()
  string(FIND "${out}${err}" "${EXPECT_OUTPUT}" found)
endif()
if(NOT code EQUAL EXPECT_EXIT OR found EQUAL -1)
  message(FATAL_ERROR "expected exit ${EXPECT_EXIT} and output containing '${EXPECT_OUTPUT}'\n"
                      "got exit ${code}\nstdout: ${out}\nstderr: ${err}")
endif()
