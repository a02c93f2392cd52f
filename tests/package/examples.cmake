# examples/ as a user builds it: a separate project, configured out of tree
# against the installed package only (find_package(Obelisk)), then run.
# cube_png (shared library) must find the shaders beside the library with no
# help; cube_png_static gets them through $OB_SHADER_DIR. Each must write a
# PNG and log no warning or error (the validation layer is on in tests).
# model_png renders BoxTextured (glTF, textured) and the same box with its
# texture taken out of the file: the two must differ on many pixels (the
# texture is drawn, ob_golden compares).
# Run by ctest: cmake -DSRC=<source> -DPREFIX=<dir> -DOUT=<dir> -DCC=<compiler>
#               -DGOLDEN=<ob_golden> -P examples.cmake
foreach(var SRC PREFIX OUT CC GOLDEN)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "package examples: -D${var}=... is required")
  endif()
endforeach()
include(${CMAKE_CURRENT_LIST_DIR}/run_example.cmake)
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SRC}/examples -B ${OUT}/build
                        -DCMAKE_PREFIX_PATH=${PREFIX} -DCMAKE_C_COMPILER=${CC}
                        -DCMAKE_BUILD_TYPE=RelWithDebInfo
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "configuring examples/ against ${PREFIX} failed\n${out}\n${err}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${OUT}/build
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "building examples/ failed\n${out}\n${err}")
endif()
if(NOT EXISTS ${OUT}/build/cube_png_static)
  message(FATAL_ERROR "the package did not offer Obelisk::obelisk_static")
endif()

ob_run_example(${OUT}/build/cube_png ${OUT}/cube.png "")
file(READ ${PREFIX}/libdir.txt libdir)
ob_run_example(${OUT}/build/cube_png_static ${OUT}/cube_static.png
               "OB_SHADER_DIR=${PREFIX}/share/obelisk/shaders")
# Same objects, same device: the same pixels.
file(SHA256 ${OUT}/cube.png a)
file(SHA256 ${OUT}/cube_static.png b)
if(NOT a STREQUAL b)
  message(FATAL_ERROR "cube_png and cube_png_static wrote different images")
endif()

# model_png: BoxTextured with its texture, then without it (the same file
# with the material's baseColorTexture removed).
set(models /usr/share/assimp/models/glTF2/BoxTextured-glTF)
ob_run_example2(${OUT}/build/model_png ${models}/BoxTextured.gltf ${OUT}/model_textured.png "")
file(COPY ${models}/BoxTextured.gltf ${models}/BoxTextured0.bin DESTINATION ${OUT}/untextured)
file(READ ${OUT}/untextured/BoxTextured.gltf gltf)
string(REGEX REPLACE "\"baseColorTexture\"[^}]*},?" "" stripped "${gltf}")
if(stripped STREQUAL gltf)
  message(FATAL_ERROR "BoxTextured.gltf has no baseColorTexture to take out")
endif()
file(WRITE ${OUT}/untextured/BoxTextured.gltf "${stripped}")
ob_run_example2(${OUT}/build/model_png ${OUT}/untextured/BoxTextured.gltf ${OUT}/model_untextured.png "")
# 640 x 480: more than 2% of the pixels must differ by more than 8 levels.
execute_process(COMMAND ${GOLDEN} ${OUT}/model_textured.png ${OUT}/model_untextured.png
                        --tolerance 8 --max-pixels 6144
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 1)
  message(FATAL_ERROR "model_png drew BoxTextured (nearly) as without its texture (ob_golden exit ${code}):\n"
                      "${out}${err}")
endif()
message(STATUS "ok: model_png drew BoxTextured's texture: ${out}")

# scene_window (built where GLFW is): a scene file shown for 5 frames in a
# window on a virtual X server, when xvfb-run is there (./setup.sh installs
# it): exits 0 and logs no warning or error, validation on.
find_program(XVFB_RUN xvfb-run)
if(EXISTS ${OUT}/build/scene_window AND XVFB_RUN)
  execute_process(COMMAND ${XVFB_RUN} -a -s "-screen 0 1024x768x24"
                          ${OUT}/build/scene_window ${SRC}/tests/data/scenes/load_small.json 5
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  if(NOT code EQUAL 0 OR err MATCHES "\\[(warn|error)\\]")
    message(FATAL_ERROR "scene_window: exit ${code}\n${out}\n${err}")
  endif()
  message(STATUS "ok: scene_window showed load_small.json for 5 frames")
else()
  message(STATUS "scene_window not run (no GLFW or no xvfb-run)")
endif()
