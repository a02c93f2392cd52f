# examples/ as a user builds it: a separate project, configured out of tree
# against the installed package only (find_package(Obelisk)), then run.
# cube_png (shared library) must find the shaders beside the library with no
# help; cube_png_static gets them through $OB_SHADER_DIR. Each must write a
# PNG and log no warning or error (the validation layer is on in tests).
# model_png renders BoxTextured (glTF, textured) and the same box with its
# texture taken out of the file: the two must differ on many pixels (the
# texture is drawn, ob_golden compares).
# The examples' compile commands name no include folder of a private
# dependency (glslang, SPIRV-Cross, assimp, cJSON), and they configure and
# build with pkg-config seeing no .pc file but Vulkan's, as on a machine
# with only the runtime libraries (Obelisk::obelisk_static is left out then).
# Run by ctest: cmake -DSRC=<source> -DPREFIX=<dir> -DOUT=<dir> -DCC=<compiler>
#               -DGOLDEN=<ob_golden> -P examples.cmake
foreach(var SRC PREFIX OUT CC GOLDEN)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "package examples: -D${var}=... is required")
  endif()
endforeach()
include(${CMAKE_CURRENT_LIST_DIR}/run_example.cmake)
file(REMOVE_RECURSE ${OUT})
# ob_build_examples(DIR ENV): configures and builds examples/ into DIR with
# ENV ("" or VAR=value) in the environment; fails unless both succeed and
# no compile command names a private dependency's include folder.
function(ob_build_examples dir env)
  set(cmd ${CMAKE_COMMAND} -S ${SRC}/examples -B ${dir} -DCMAKE_PREFIX_PATH=${PREFIX}
          -DCMAKE_C_COMPILER=${CC} -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_EXPORT_COMPILE_COMMANDS=ON)
  if(env)
    set(cmd ${CMAKE_COMMAND} -E env ${env} ${cmd})
  endif()
  execute_process(COMMAND ${cmd} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "configuring examples/ against ${PREFIX} (${env}) failed\n${out}\n${err}")
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} --build ${dir}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "building examples/ (${env}) failed\n${out}\n${err}")
  endif()
  file(READ ${dir}/compile_commands.json commands)
  if(commands MATCHES "(-I|-isystem +)[^ \"]*(glslang|spirv|assimp|cjson)")
    message(FATAL_ERROR "an example is compiled with a private dependency's include folder "
                        "(${CMAKE_MATCH_0}):\n${commands}")
  endif()
endfunction()

ob_build_examples(${OUT}/build "")
if(NOT EXISTS ${OUT}/build/cube_png_static)
  message(FATAL_ERROR "the package did not offer Obelisk::obelisk_static")
endif()

# Only Vulkan's .pc file to be seen: the shared-library examples still build.
execute_process(COMMAND pkg-config --variable=pcfiledir vulkan OUTPUT_VARIABLE vulkan_pc_dir
                OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE code)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "pkg-config finds no vulkan.pc")
endif()
file(COPY ${vulkan_pc_dir}/vulkan.pc DESTINATION ${OUT}/runtime-only-pc)
ob_build_examples(${OUT}/build-runtime-only "PKG_CONFIG_LIBDIR=${OUT}/runtime-only-pc")
foreach(exe cube_png model_png)
  if(NOT EXISTS ${OUT}/build-runtime-only/${exe})
    message(FATAL_ERROR "${exe} was not built without the private dependencies' .pc files")
  endif()
endforeach()
message(STATUS "ok: examples build with only Vulkan's pkg-config file present")

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
