# obelisk.pc as a user reads it, on a machine with only the runtime
# libraries and Obelisk's own headers: pkg-config sees no .pc file but
# Vulkan's and Obelisk's (PKG_CONFIG_LIBDIR), `pkg-config --cflags` names no
# private dependency (glslang, SPIRV-Cross, assimp, cJSON), and
# `cc cube_png.c $(pkg-config --cflags --libs obelisk)` and model_png.c the
# same way link the shared library of the install tree and run
# (LD_LIBRARY_PATH finds the library, the library finds its shaders).
# `pkg-config --static --libs obelisk` links libobelisk.a: cube_png linked
# so draws the same pixels.
# Run by ctest: cmake -DSRC=<source> -DPREFIX=<dir> -DOUT=<dir> -DCC=<compiler> -P pkgconfig.cmake
foreach(var SRC PREFIX OUT CC)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "package pkg-config: -D${var}=... is required")
  endif()
endforeach()
include(${CMAKE_CURRENT_LIST_DIR}/run_example.cmake)
find_program(PKG_CONFIG pkg-config REQUIRED)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT}/pc)
file(READ ${PREFIX}/libdir.txt libdir)
execute_process(COMMAND ${PKG_CONFIG} --variable=pcfiledir vulkan OUTPUT_VARIABLE vulkan_pc_dir
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "pkg-config finds no vulkan.pc")
endif()
file(COPY ${vulkan_pc_dir}/vulkan.pc DESTINATION ${OUT}/pc)
set(ENV{PKG_CONFIG_LIBDIR} ${OUT}/pc)
set(ENV{PKG_CONFIG_PATH} ${PREFIX}/${libdir}/pkgconfig)

# ob_pkg_config(VAR ARGS...): VAR = `pkg-config ARGS... obelisk`, split.
function(ob_pkg_config var)
  execute_process(COMMAND ${PKG_CONFIG} ${ARGN} obelisk
                  RESULT_VARIABLE code OUTPUT_VARIABLE flags ERROR_VARIABLE err
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "pkg-config ${ARGN} obelisk failed with only vulkan.pc beside it\n${err}")
  endif()
  separate_arguments(flags UNIX_COMMAND "${flags}")
  set(${var} ${flags} PARENT_SCOPE)
endfunction()

ob_pkg_config(cflags --cflags)
if(cflags MATCHES "glslang|spirv|assimp|cjson|cJSON")
  message(FATAL_ERROR "pkg-config --cflags obelisk names a private dependency: ${cflags}")
endif()
ob_pkg_config(flags --cflags --libs)
foreach(example cube_png model_png)
  execute_process(COMMAND ${CC} -std=c11 -Wall -Wextra -Werror ${SRC}/examples/${example}.c ${flags}
                          -o ${OUT}/${example}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "cc ${example}.c $(pkg-config --cflags --libs obelisk) failed\n${out}\n${err}")
  endif()
endforeach()
set(env "LD_LIBRARY_PATH=${PREFIX}/${libdir}")
ob_run_example(${OUT}/cube_png ${OUT}/cube.png ${env})
ob_run_example2(${OUT}/model_png /usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb
                ${OUT}/box.png ${env})

# Static: the same flags with --static, libobelisk.a in place of -lobelisk.
ob_pkg_config(static_flags --cflags --static --libs)
list(TRANSFORM static_flags REPLACE "^-lobelisk$" "${PREFIX}/${libdir}/libobelisk.a")
execute_process(COMMAND ${CC} -std=c11 -Wall -Wextra -Werror ${SRC}/examples/cube_png.c ${static_flags}
                        -o ${OUT}/cube_png_static
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "cc cube_png.c $(pkg-config --cflags --static --libs obelisk) with libobelisk.a "
                      "failed\n${static_flags}\n${out}\n${err}")
endif()
ob_run_example(${OUT}/cube_png_static ${OUT}/cube_static.png
               "OB_SHADER_DIR=${PREFIX}/share/obelisk/shaders")
file(SHA256 ${OUT}/cube.png a)
file(SHA256 ${OUT}/cube_static.png b)
if(NOT a STREQUAL b)
  message(FATAL_ERROR "cube_png linked with pkg-config --static drew other pixels than the shared one")
endif()
message(STATUS "ok: pkg-config --static links libobelisk.a (same pixels)")
