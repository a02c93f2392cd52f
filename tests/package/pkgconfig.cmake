# obelisk.pc as a user reads it: cube_png compiled with one compiler call,
# `cc cube_png.c $(pkg-config --cflags --libs obelisk)`, linking the shared
# library of the install tree, then run (LD_LIBRARY_PATH finds the library,
# the library finds its shaders).
# Run by ctest: cmake -DSRC=<source> -DPREFIX=<dir> -DOUT=<dir> -DCC=<compiler> -P pkgconfig.cmake
foreach(var SRC PREFIX OUT CC)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "package pkg-config: -D${var}=... is required")
  endif()
endforeach()
include(${CMAKE_CURRENT_LIST_DIR}/run_example.cmake)
find_program(PKG_CONFIG pkg-config REQUIRED)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
file(READ ${PREFIX}/libdir.txt libdir)
set(ENV{PKG_CONFIG_PATH} ${PREFIX}/${libdir}/pkgconfig)
execute_process(COMMAND ${PKG_CONFIG} --cflags --libs obelisk
                RESULT_VARIABLE code OUTPUT_VARIABLE flags ERROR_VARIABLE err
                OUTPUT_STRIP_TRAILING_WHITESPACE)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "pkg-config --cflags --libs obelisk failed\n${err}")
endif()
separate_arguments(flags UNIX_COMMAND "${flags}")
execute_process(COMMAND ${CC} -std=c11 -Wall -Wextra -Werror ${SRC}/examples/cube_png.c ${flags}
                        -o ${OUT}/cube_png
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "cc cube_png.c $(pkg-config --cflags --libs obelisk) failed\n${out}\n${err}")
endif()
ob_run_example(${OUT}/cube_png ${OUT}/cube.png "LD_LIBRARY_PATH=${PREFIX}/${libdir}")
