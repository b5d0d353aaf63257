# ctest script: builds the .tar.gz package with CPack into OUT and checks that it holds the
# programs and the desktop integration (so packaging cannot rot unnoticed).
file(REMOVE_RECURSE "${OUT}")
execute_process(COMMAND "${CPACK}" --config "${CONFIG}" -G TGZ -B "${OUT}"
                RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "cpack failed:\n${output}")
endif()
file(GLOB tarballs "${OUT}/*.tar.gz")
list(LENGTH tarballs count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "expected one .tar.gz in ${OUT}, found ${count}")
endif()
execute_process(COMMAND tar tzf ${tarballs} OUTPUT_VARIABLE listing RESULT_VARIABLE result)
foreach(expected bin/omicron-cli bin/omicron-cli-render bin/omicron share/applications/omicron.desktop
        share/icons/hicolor/scalable/apps/omicron.svg)
  string(FIND "${listing}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "package lacks ${expected}:\n${listing}")
  endif()
endforeach()
file(REMOVE_RECURSE "${OUT}")
