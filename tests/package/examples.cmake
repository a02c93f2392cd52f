# examples/ as a user builds it: a separate project, configured out of tree
# against the installed package only (find_package(Obelisk)), then run.
# cube_png (shared library) must find the shaders beside the library with no
# help; cube_png_static gets them through $OB_SHADER_DIR. Each must write a
# PNG and log no warning or error (the validation layer is on in tests).
# Run by ctest: cmake -DSRC=<source> -DPREFIX=<dir> -DOUT=<dir> -DCC=<compiler> -P examples.cmake
foreach(var SRC PREFIX OUT CC)
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
