# ctest script: runs one benchmark on a small input so the benchmarks keep working; checks only
# that it exits 0 and prints its machine-readable lines (timings are never asserted).
# Exits 77 (skipped) when the shared data file it needs is absent.
if(DEFINED INPUT AND NOT EXISTS "${INPUT}")
  message("skipped: ${INPUT} is absent (../shared/data)")
  cmake_language(EXIT 77)
endif()
execute_process(COMMAND ${BENCH} ${ARGS} RESULT_VARIABLE result OUTPUT_VARIABLE output
                ERROR_VARIABLE errors)
message("${output}")
if(NOT result EQUAL 0)
  message(FATAL_ERROR "benchmark failed (${result}):\n${errors}")
endif()
if(NOT output MATCHES "bench=")
  message(FATAL_ERROR "benchmark printed no 'bench=' line")
endif()
