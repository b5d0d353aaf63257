# The .oms and .omh fuzz seeds: bunny.ply sorted and built (depth 4, so the seeds stay small),
# the .omh in format versions 4, 3 and 2.
file(MAKE_DIRECTORY ${OUT})
if(NOT EXISTS ${SOURCE})
  message(STATUS "no ${SOURCE}: the .oms and .omh fuzz targets will skip")
  return()
endif()
execute_process(COMMAND ${CLI} sort ${SOURCE} ${OUT}/bunny.oms RESULT_VARIABLE sorted)
execute_process(COMMAND ${CLI} build ${SOURCE} --depth 4 --save ${OUT}/bunny.omh
                RESULT_VARIABLE built OUTPUT_QUIET)
# A version 2 file too (splat attributes in every record): the reader still loads those.
execute_process(COMMAND ${CLI} build ${SOURCE} --depth 4 --save ${OUT}/bunny-v2.omh
                        --save-version 2
                RESULT_VARIABLE builtV2 OUTPUT_QUIET)
# And version 3 (every level as records; version 4 stores the deepest as columns).
execute_process(COMMAND ${CLI} build ${SOURCE} --depth 4 --save ${OUT}/bunny-v3.omh
                        --save-version 3
                RESULT_VARIABLE builtV3 OUTPUT_QUIET)
if(NOT sorted EQUAL 0 OR NOT built EQUAL 0 OR NOT builtV2 EQUAL 0 OR NOT builtV3 EQUAL 0)
  message(FATAL_ERROR
          "omicron-cli could not make the fuzz seeds (${sorted}, ${built}, ${builtV2}, ${builtV3})")
endif()
