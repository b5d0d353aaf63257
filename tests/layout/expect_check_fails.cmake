# Runs the core's include-direction check on a fixture and passes only when the check fails
# with the expected message:  cmake -DCHECK=<script> -DCORE_DIR=<fixture> -DEXPECTED=<regex> -P
execute_process(COMMAND ${CMAKE_COMMAND} -DCORE_DIR=${CORE_DIR} -P ${CHECK}
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(status EQUAL 0)
  message(FATAL_ERROR "the check accepted ${CORE_DIR}, which plants a forbidden include:\n${out}${err}")
endif()
if(NOT "${out}${err}" MATCHES "${EXPECTED}")
  message(FATAL_ERROR "the check failed on ${CORE_DIR} without saying '${EXPECTED}':\n${out}${err}")
endif()
message("the check rejects ${CORE_DIR}: ${EXPECTED}")
