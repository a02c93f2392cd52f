# golden_update.cmake — regenerates tests/golden/*.png (./setup.sh golden):
# renders every ob_golden() of tests/golden/goldens.cmake (or only the names
# in ONLY) single-threaded, says per image what changed against the golden
# it replaces ("new", "unchanged", or "changed: N pixels differ by more than
# the tolerance, largest difference D") and copies it over. Review the new
# images (git diff --stat, an image viewer) before committing them.
# Run as: cmake -DBIN=<build>/bin -DTOOL=<ob_golden> -DSRC=<source> -DOUT=<dir> [-DONLY="a;b"] -P golden_update.cmake
cmake_minimum_required(VERSION 3.25)
foreach(var BIN TOOL SRC OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "golden_update: -D${var}=... is required")
  endif()
endforeach()
include(${CMAKE_CURRENT_LIST_DIR}/golden_render.cmake)
file(MAKE_DIRECTORY ${OUT})

function(ob_golden name input)
  set_property(GLOBAL APPEND PROPERTY OB_GOLDEN_SEEN ${name})
  if(ONLY AND NOT name IN_LIST ONLY)
    return()
  endif()
  ob_golden_input(${input} path)
  if(NOT EXISTS ${path})
    message("${name}: skipped, ${path} is not installed")
    return()
  endif()
  set(golden ${SRC}/tests/golden/${name}.png)
  ob_golden_render(${path} ${OUT}/${name}.png 0 ${ARGN})
  execute_process(COMMAND ${TOOL} ${OUT}/${name}.png ${golden} --report
                  RESULT_VARIABLE code OUTPUT_VARIABLE what ERROR_VARIABLE err
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT code STREQUAL "0")
    message(FATAL_ERROR "${name}: ob_golden failed: ${err}")
  endif()
  if(NOT what STREQUAL "unchanged")
    file(COPY_FILE ${OUT}/${name}.png ${golden})
  endif()
  file(SIZE ${golden} size)
  message("${name}: ${what} (${size} bytes)")
endfunction()
macro(ob_golden_device_tolerance)   # the goldens are lavapipe's: read by golden_test.cmake only
endmacro()
include(${SRC}/tests/golden/goldens.cmake)

get_property(seen GLOBAL PROPERTY OB_GOLDEN_SEEN)
foreach(name ${ONLY})
  if(NOT name IN_LIST seen)
    message(FATAL_ERROR "golden_update: no golden named '${name}' in tests/golden/goldens.cmake")
  endif()
endforeach()
file(GLOB pngs ${SRC}/tests/golden/*.png)
foreach(png ${pngs})
  get_filename_component(name ${png} NAME_WE)
  if(NOT name IN_LIST seen)
    message("${name}: tests/golden/${name}.png has no ob_golden() entry (remove it?)")
  endif()
endforeach()
