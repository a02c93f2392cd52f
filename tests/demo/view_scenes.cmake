# obelisk-view renders every shipped scene (demos/scenes/*.json) and one model
# file given directly, each for 3 frames, exiting 0 (with OB_VALIDATION=1 in
# the environment, 0 also means the validation layer reported nothing) and
# writing its PNG.
# Run by ctest: cmake -DBIN=<build>/bin -DSRC=<source> -DOUT=<dir> -P view_scenes.cmake
foreach(var BIN SRC OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "view_scenes: -D${var}=... is required")
  endif()
endforeach()
file(MAKE_DIRECTORY ${OUT})

function(render input png)
  file(REMOVE ${png})
  execute_process(COMMAND ${BIN}/obelisk-view ${input} --frames 3 --quiet --out ${png}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
  if(NOT code STREQUAL "0")
    message(FATAL_ERROR "obelisk-view ${input}: exit ${code}\n${out}\n${err}")
  endif()
  if(NOT out MATCHES "wrote ")
    message(FATAL_ERROR "obelisk-view ${input}: no 'wrote' line\n${out}\n${err}")
  endif()
  if(err MATCHES "did not load|\\[error\\]")
    message(FATAL_ERROR "obelisk-view ${input}: errors on a clean input\n${err}")
  endif()
  if(NOT EXISTS ${png})
    message(FATAL_ERROR "obelisk-view ${input}: ${png} was not written")
  endif()
  file(SIZE ${png} size)
  if(size LESS 1000)
    message(FATAL_ERROR "obelisk-view ${input}: ${png} is only ${size} bytes")
  endif()
  message(STATUS "ok: ${input} -> ${png}")
endfunction()

file(GLOB scenes ${SRC}/demos/scenes/*.json)
list(LENGTH scenes count)
if(count LESS 3)
  message(FATAL_ERROR "expected at least 3 scenes in ${SRC}/demos/scenes, found ${count}")
endif()
foreach(scene ${scenes})
  get_filename_component(name ${scene} NAME_WE)
  render(${scene} ${OUT}/${name}.png)
endforeach()

render(/usr/share/assimp/models/PLY/Wuson.ply ${OUT}/model-Wuson.png)
