# demos/scenes/mirror.json is obelisk-mirror's scene: obelisk-mirror-scene
# writes it from the one definition (demos/scenes/ob_mirror_scene.c), and the
# checked-in file must be byte for byte what it writes now (else it is stale:
# regenerate it), and loading it (ob_scene_load) must give the scene the
# definition builds: same nodes, transforms over several frames, geometry,
# materials, lights, camera and final image (obelisk-mirror-scene --check).
# Run by ctest: cmake -DBIN=<build>/bin -DSRC=<source> -DOUT=<dir> -P mirror_scene_file.cmake
cmake_minimum_required(VERSION 3.25)
foreach(var BIN SRC OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "mirror_scene_file: -D${var}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})

execute_process(COMMAND ${BIN}/obelisk-mirror-scene --out ${OUT}/mirror.json
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "obelisk-mirror-scene --out exited with ${rc}\n${err}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${SRC}/demos/scenes/mirror.json
                        ${OUT}/mirror.json RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  message(FATAL_ERROR "demos/scenes/mirror.json is stale: it is not what the definition "
          "(demos/scenes/ob_mirror_scene.c) writes now. Regenerate it:\n"
          "  build/bin/obelisk-mirror-scene --out demos/scenes/mirror.json\n"
          "(the fresh output is ${OUT}/mirror.json)")
endif()

execute_process(COMMAND ${BIN}/obelisk-mirror-scene --check ${SRC}/demos/scenes/mirror.json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "loading demos/scenes/mirror.json does not give the defined scene (${rc})\n${out}\n${err}")
endif()
message(STATUS "${out}")
