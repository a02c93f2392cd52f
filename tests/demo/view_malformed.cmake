# Bad input to obelisk-view: each tests/data/scenes/bad_*.json exits with code
# 2 and prints the message in its bad_*.expect sidecar (the JSON path and what
# was expected); a scene whose models do not load renders the rest, names
# each failed entity and its file, and exits 2 -- or 0 with --allow-missing.
# Run by ctest: cmake -DBIN=<build>/bin -DSRC=<source> -DOUT=<dir> -P view_malformed.cmake
foreach(var BIN SRC OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "view_malformed: -D${var}=... is required")
  endif()
endforeach()
file(MAKE_DIRECTORY ${OUT})
set(data ${SRC}/tests/data/scenes)

file(GLOB bad_files ${data}/bad_*.json)
list(LENGTH bad_files count)
if(count LESS 10)
  message(FATAL_ERROR "expected at least 10 bad_*.json files in ${data}, found ${count}")
endif()
foreach(bad ${bad_files})
  get_filename_component(name ${bad} NAME_WE)
  file(READ ${data}/${name}.expect expected)
  string(STRIP "${expected}" expected)
  execute_process(COMMAND ${BIN}/obelisk-view ${bad} --frames 1 --quiet --out ${OUT}/${name}.png
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  if(NOT code STREQUAL "2")
    message(FATAL_ERROR "${name}: exit ${code}, expected 2\n${out}\n${err}")
  endif()
  string(FIND "${err}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${name}: stderr lacks '${expected}'\n${err}")
  endif()
  if(EXISTS ${OUT}/${name}.png)
    message(FATAL_ERROR "${name}: an image was written for a malformed scene")
  endif()
  message(STATUS "ok: ${name}: ${err}")
endforeach()

# Models that do not load: reported by entity and file, the rest renders.
set(png ${OUT}/missing_model.png)
file(REMOVE ${png})
execute_process(COMMAND ${BIN}/obelisk-view ${data}/missing_model.json --frames 3 --quiet --out ${png}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
if(NOT code STREQUAL "2")
  message(FATAL_ERROR "missing_model: exit ${code}, expected 2 (models missing, no --allow-missing)\n${out}\n${err}")
endif()
foreach(expected
        "entities[2] 'ghost': model '${data}/no-such-model.obj' did not load"
        "entities[4] 'ghost-twin': model '${data}/no-such-model.obj' did not load"
        "entities[5] 'infinite-box': model '/usr/share/assimp/models/glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb' did not load"
        "no-such-model.obj: cannot open model file: No such file or directory"
        "position is not finite"
        "obelisk-view: ${data}/missing_model.json: 3 entities were left out because their model did not load:"
        "  entities[2] 'ghost': model '${data}/no-such-model.obj' (OB_ERR_IO)"
        "--allow-missing accepts this and exits 0")
  string(FIND "${err}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "missing_model: stderr lacks '${expected}'\n${err}")
  endif()
endforeach()
if(NOT out MATCHES "6 entities \\(3 left out\\)")
  message(FATAL_ERROR "missing_model: the summary does not count 3 entities left out\n${out}")
endif()
if(NOT EXISTS ${png})
  message(FATAL_ERROR "missing_model: ${png} was not written")
endif()
# --allow-missing: the same render is what the user asked for.
execute_process(COMMAND ${BIN}/obelisk-view ${data}/missing_model.json --frames 1 --quiet --allow-missing
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
if(NOT code STREQUAL "0")
  message(FATAL_ERROR "missing_model --allow-missing: exit ${code}, expected 0\n${out}\n${err}")
endif()
message(STATUS "ok: missing_model renders the rest, exits 2, and 0 with --allow-missing:\n${err}")
