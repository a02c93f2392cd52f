# golden_test.cmake — one golden image test (ctest golden_NAME, label
# golden): renders NAME's input from tests/golden/goldens.cmake twice, single-
# threaded (--threads 0) and with two workers (--threads 2), requires the two
# to be pixel-identical (recording is byte-identical by design) and each to
# match tests/golden/NAME.png within ob_golden's tolerance. On a mismatch
# ob_golden writes OUT/NAME.st.diff.png (or .mt.diff.png) and prints its path.
# Prints "SKIP: ..." when the input is a model that is not installed.
# Run by ctest as:
#   cmake -DBIN=<build>/bin -DTOOL=<ob_golden> -DSRC=<source> -DOUT=<dir> -DNAME=<name> -P golden_test.cmake
cmake_minimum_required(VERSION 3.25)
foreach(var BIN TOOL SRC OUT NAME)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "golden_test: -D${var}=... is required")
  endif()
endforeach()
include(${CMAKE_CURRENT_LIST_DIR}/golden_render.cmake)

macro(ob_golden name input)
  if("${name}" STREQUAL "${NAME}")
    set(found_input ${input})
    set(found_args ${ARGN})
  endif()
endmacro()
# ob_golden_device_tolerance(NAME MAX_PIXELS REASON): on a device other than
# lavapipe (which made the goldens), up to MAX_PIXELS may differ by more than
# 2; lavapipe keeps the strict bound. Only for differences the Vulkan spec
# leaves to the implementation, with REASON saying which (docs/testing.md).
macro(ob_golden_device_tolerance name max_pixels reason)
  if("${name}" STREQUAL "${NAME}")
    set(device_max_pixels ${max_pixels})
    set(device_reason "${reason}")
  endif()
endmacro()
include(${SRC}/tests/golden/goldens.cmake)
if(NOT DEFINED found_input)
  message(FATAL_ERROR "golden_test: no ob_golden(${NAME} ...) in tests/golden/goldens.cmake")
endif()
ob_golden_input(${found_input} input)
if(NOT EXISTS ${input})
  message("SKIP: ${input} is not installed (assimp-testmodels)")
  return()
endif()

file(MAKE_DIRECTORY ${OUT})
set(golden ${SRC}/tests/golden/${NAME}.png)
file(REMOVE ${OUT}/${NAME}.st.diff.png ${OUT}/${NAME}.mt.diff.png ${OUT}/${NAME}.st-vs-mt.diff.png)
ob_golden_render(${input} ${OUT}/${NAME}.st.png 0 ${found_args})
ob_golden_render(${input} ${OUT}/${NAME}.mt.png 2 ${found_args})

function(compare image reference tolerance max_pixels diff)
  execute_process(COMMAND ${TOOL} ${image} ${reference} ${tolerance} ${max_pixels} --diff ${diff}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message(STATUS "${image}: ${out}${err}")
  if(NOT code STREQUAL "0")
    message(FATAL_ERROR "golden ${NAME}: ${image} does not match ${reference}\n${out}${err}"
                        "If the change is intended: ./setup.sh golden ${NAME}, view the image, commit it.")
  endif()
endfunction()
compare(${OUT}/${NAME}.mt.png ${OUT}/${NAME}.st.png "--tolerance;0" "--max-pixels;0"
        ${OUT}/${NAME}.st-vs-mt.diff.png)
set(golden_max_pixels "")
if(DEFINED device_max_pixels AND NOT "${OB_GOLDEN_DEVICE}" MATCHES "^llvmpipe")
  set(golden_max_pixels "--max-pixels;${device_max_pixels}")
  message(STATUS "golden ${NAME} on '${OB_GOLDEN_DEVICE}': up to ${device_max_pixels} pixels may differ "
                 "(${device_reason})")
endif()
compare(${OUT}/${NAME}.st.png ${golden} "" "${golden_max_pixels}" ${OUT}/${NAME}.st.diff.png)
compare(${OUT}/${NAME}.mt.png ${golden} "" "${golden_max_pixels}" ${OUT}/${NAME}.mt.diff.png)
