# obelisk-mirror headless under validation: single-threaded, two workers and
# toggling every frame must exit 0 (3 = the validation layer spoke) and write
# byte-identical images; the stats JSON must parse and carry equal hashes.
file(MAKE_DIRECTORY ${OUT})
set(common --frames 4 --size 320x240 --objects 120 --quiet)

function(run_mirror name)
  execute_process(COMMAND ${BIN}/obelisk-mirror ${common} ${ARGN}
                          --out ${OUT}/${name}.png --stats-json ${OUT}/${name}.json
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "obelisk-mirror ${ARGN} exited with ${rc}\n${out}\n${err}")
  endif()
  if(NOT out MATCHES "summary: median ms per phase")
    message(FATAL_ERROR "obelisk-mirror ${ARGN}: no summary in its output\n${out}")
  endif()
endfunction()

run_mirror(st --threads 0)
run_mirror(mt --threads 2)
run_mirror(toggle --threads 2 --toggle 1)

foreach(other mt toggle)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}/st.png ${OUT}/${other}.png
                  RESULT_VARIABLE same)
  if(NOT same EQUAL 0)
    message(FATAL_ERROR "the ${other} image differs from the single-threaded one")
  endif()
endforeach()

# Per-frame command hashes agree across modes.
function(frame_hashes file outvar)
  file(READ ${file} json)
  string(JSON n LENGTH "${json}")
  math(EXPR last "${n} - 1")
  set(hashes "")
  foreach(i RANGE ${last})
    string(JSON h GET "${json}" ${i} frame_hash)
    string(JSON mode GET "${json}" ${i} mode)
    list(APPEND hashes ${h})
  endforeach()
  set(${outvar} "${hashes}" PARENT_SCOPE)
endfunction()
frame_hashes(${OUT}/st.json st_hashes)
frame_hashes(${OUT}/mt.json mt_hashes)
frame_hashes(${OUT}/toggle.json toggle_hashes)
if(NOT st_hashes STREQUAL mt_hashes OR NOT st_hashes STREQUAL toggle_hashes)
  message(FATAL_ERROR "command hashes differ:\n ST ${st_hashes}\n MT ${mt_hashes}\n toggle ${toggle_hashes}")
endif()
file(READ ${OUT}/toggle.json json)
string(JSON m0 GET "${json}" 0 mode)
string(JSON m1 GET "${json}" 1 mode)
if(m0 STREQUAL m1)
  message(FATAL_ERROR "--toggle 1 did not switch modes between frames (${m0}, ${m1})")
endif()
