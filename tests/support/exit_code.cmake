# Driven by ctest (Tools.*): runs EXE with ARGS (a ;-list) and fails unless it exits with
# EXPECT (a crash or abort is no exit code) and, when given, its output matches MATCH.
separate_arguments(args UNIX_COMMAND "${ARGS}")
execute_process(COMMAND "${EXE}" ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc STREQUAL "${EXPECT}")
  message(FATAL_ERROR "${EXE} ${ARGS}: exit '${rc}', expected ${EXPECT}:\n${out}${err}")
endif()
if(DEFINED MATCH AND NOT "${out}${err}" MATCHES "${MATCH}")
  message(FATAL_ERROR "${EXE} ${ARGS}: output does not match '${MATCH}':\n${out}${err}")
endif()
