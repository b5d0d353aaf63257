# ctest script: runs one benchmark on a small input so the benchmarks keep working; checks only
# that it exits 0 and prints its machine-readable lines (timings are never asserted).
# When the shared data file it needs is absent it prints "skipped: ..." and stops, which the
# tests' SKIP_REGULAR_EXPRESSION reports as skipped (cmake_language(EXIT) needs CMake 3.29;
# Debian 12 has 3.25).
if(DEFINED INPUT AND NOT EXISTS "${INPUT}")
  message("skipped: ${INPUT} is absent (../shared/data)")
  return()
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
