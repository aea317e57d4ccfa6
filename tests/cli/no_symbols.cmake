# Fails when BINARY defines a symbol matching PATTERN (an extended regex over demangled names):
# e.g. the localizer's test binary must not contain simulator code.
#   cmake -DNM=nm -DBINARY=file -DPATTERN=regex -P no_symbols.cmake
execute_process(COMMAND ${NM} -C --defined-only ${BINARY} OUTPUT_VARIABLE symbols RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${NM} failed on ${BINARY}")
endif()
string(REGEX MATCHALL "[^\n]*(${PATTERN})[^\n]*" found "${symbols}")
list(LENGTH found count)
if(count GREATER 0)
  list(GET found 0 first)
  message(FATAL_ERROR "${BINARY} defines ${count} symbols matching '${PATTERN}', e.g. ${first}")
endif()
string(REGEX MATCHALL "\n" lines "${symbols}")
list(LENGTH lines total)
message(STATUS "${BINARY}: none of its ${total} symbols match '${PATTERN}'")
