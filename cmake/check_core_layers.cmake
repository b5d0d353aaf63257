# Keeps the core's dependencies pointing one way, down the pipeline (docs/ARCHITECTURE.md,
# "Folder map"). Run as a script:  cmake -DCORE_DIR=<src/core> -P check_core_layers.cmake
#
# Every quoted include in a core source must name its folder ("build/hierarchy.hpp") and that
# folder must be one the including stage may use; nothing in the core may include from outside
# it (widget, app, cli) nor a Qt or OpenGL header. Files directly in CORE_DIR belong to every
# stage: they may include no stage, and every stage may include them. The first violation does
# not stop the scan: all of them are printed, then the script fails.
cmake_minimum_required(VERSION 3.25)

if(NOT DEFINED CORE_DIR OR NOT IS_DIRECTORY "${CORE_DIR}")
  message(FATAL_ERROR "check_core_layers: set -DCORE_DIR to the core's source folder")
endif()
get_filename_component(CORE_DIR "${CORE_DIR}" ABSOLUTE)

# What each stage may include besides itself; the order is the pipeline's.
set(stages points io scene sort build formats front pipeline)
set(allowed_points "")
set(allowed_io points)
set(allowed_scene points)
set(allowed_sort points io)
set(allowed_build points sort)
set(allowed_formats points io sort build)
set(allowed_front points build)
set(allowed_pipeline points io scene sort build formats)

file(GLOB_RECURSE sources LIST_DIRECTORIES false RELATIVE "${CORE_DIR}"
     "${CORE_DIR}/*.hpp" "${CORE_DIR}/*.cpp" "${CORE_DIR}/*.h")
list(SORT sources)

set(violations 0)
set(files_checked 0)
set(includes_checked 0)
foreach(source ${sources})
  math(EXPR files_checked "${files_checked} + 1")
  string(FIND "${source}" "/" slash)
  if(slash EQUAL -1)
    set(stage "") # shared by every stage
  else()
    string(SUBSTRING "${source}" 0 ${slash} stage)
    if(NOT stage IN_LIST stages)
      message("${CORE_DIR}/${source}: folder '${stage}' is not a stage of the core; add it to "
              "the rules in cmake/check_core_layers.cmake and to docs/ARCHITECTURE.md")
      math(EXPR violations "${violations} + 1")
      continue()
    endif()
  endif()

  file(STRINGS "${CORE_DIR}/${source}" include_lines REGEX "^[ \t]*#[ \t]*include")
  foreach(line ${include_lines})
    math(EXPR includes_checked "${includes_checked} + 1")
    set(where "${CORE_DIR}/${source}: '${line}'")
    if(line MATCHES "<(Q[A-Za-z]|qt|qopengl|GL/|GLES|glad|epoxy)")
      message("${where}: the core uses neither Qt nor OpenGL")
      math(EXPR violations "${violations} + 1")
      continue()
    endif()
    if(NOT line MATCHES "\"([^\"]+)\"")
      continue() # a system or third-party header
    endif()
    set(target "${CMAKE_MATCH_1}")
    string(FIND "${target}" "/" target_slash)
    if(target_slash EQUAL -1)
      # Only a file shared by every stage sits in CORE_DIR itself.
      if(NOT EXISTS "${CORE_DIR}/${target}")
        message("${where}: include paths say the folder (e.g. \"build/hierarchy.hpp\")")
        math(EXPR violations "${violations} + 1")
      endif()
      continue()
    endif()
    string(SUBSTRING "${target}" 0 ${target_slash} target_stage)
    if(NOT target_stage IN_LIST stages OR NOT EXISTS "${CORE_DIR}/${target}")
      message("${where}: not a file of the core; the core includes nothing from widget, app "
              "or cli, and no relative path")
      math(EXPR violations "${violations} + 1")
      continue()
    endif()
    if(stage STREQUAL "")
      message("${where}: a file shared by every stage may include no stage")
      math(EXPR violations "${violations} + 1")
      continue()
    endif()
    if(target_stage STREQUAL stage OR target_stage IN_LIST allowed_${stage})
      continue()
    endif()
    string(REPLACE ";" " " may "${allowed_${stage}}")
    message("${where}: ${stage} may not include ${target_stage} (dependencies point down the "
            "pipeline; ${stage} may include: ${may})")
    math(EXPR violations "${violations} + 1")
  endforeach()
endforeach()

if(files_checked EQUAL 0)
  message(FATAL_ERROR "check_core_layers: no source under ${CORE_DIR}")
endif()
if(violations GREATER 0)
  message(FATAL_ERROR "check_core_layers: ${violations} include(s) cross a forbidden direction")
endif()
message("check_core_layers: ${files_checked} files, ${includes_checked} includes, all pointing "
        "down the pipeline")
