# Hostile input to obelisk-view (issue 26), as a user meets it: nothing hangs,
# nothing outside the input's folder is read, nothing at an output path is
# replaced that is not a regular file, and every value out of its range is
# refused with exit 2 naming it. Each run has a timeout far above its need: a
# FIFO that blocked would fail the test by timing out, not hang CI.
# Run by ctest: cmake -DBIN=<build>/bin -DSRC=<source> -DOUT=<dir> -P view_hostile.cmake
foreach(var BIN SRC OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "view_hostile: -D${var}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT}/scenes/sub)
set(models ${SRC}/tests/data/models)
set(quad ${models}/mtl_quad.obj)
find_program(MKFIFO mkfifo REQUIRED)

# view(NAME EXPECTED_EXIT STDERR_NEEDLE args...): runs obelisk-view, checks
# the exit code and that stderr holds the needle.
function(view name expected needle)
  execute_process(COMMAND ${BIN}/obelisk-view ${ARGN} --quiet
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
  if(NOT code STREQUAL "${expected}")
    message(FATAL_ERROR "${name}: exit ${code}, expected ${expected}\n${out}\n${err}")
  endif()
  if(needle)
    string(FIND "${err}" "${needle}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "${name}: stderr lacks '${needle}'\n${err}")
    endif()
  endif()
  set(last_out "${out}" PARENT_SCOPE)
  message(STATUS "ok: ${name}")
endfunction()

# --- Values: one range per setting, the same on the command line and in a file.
view(size_wraps 2 "bad value '4294967297x1' for --size: expected WxH, each side from 1 to 8192"
     ${quad} --size 4294967297x1)
view(size_trailing 2 "bad value '12x34x56' for --size" ${quad} --size 12x34x56)
view(exposure_cli 2 "bad value '1e20' for --exposure: expected a number from 1e-06 to 1e+06"
     ${quad} --exposure 1e20)
file(WRITE ${OUT}/scenes/exposure.json "{\"settings\": {\"exposure\": 1e20}, \"entities\": []}")
view(exposure_file 2 "exposure.json: settings.exposure: expected a number from 1e-06 to 1e+06, got 1e+20"
     ${OUT}/scenes/exposure.json)
view(unknown_last_option 2 "unknown argument '--bogus'" ${quad} --bogus)

# --- FIFOs: as the scene file, and as a model's texture (dropped, said so).
execute_process(COMMAND ${MKFIFO} ${OUT}/scenes/fifo.json)
view(scene_fifo 2 "fifo.json: cannot open the scene file: not a regular file (a FIFO)" ${OUT}/scenes/fifo.json)

# --- A scene's relative model path must stay in the scene's folder.
file(COPY ${models}/mtl_quad.obj ${models}/mtl_quad.mtl ${models}/checker.png ${models}/normal.png
          ${models}/height.png DESTINATION ${OUT}/scenes)
file(WRITE ${OUT}/scenes/sub/escape.json
     "{\"entities\": [{\"name\": \"floor\", \"geometry\": {\"generator\": \"box\"}},
                      {\"name\": \"escapee\", \"geometry\": {\"model\": \"../mtl_quad.obj\"}}]}")
view(scene_escape 2 "entities[1] 'escapee': refused model" ${OUT}/scenes/sub/escape.json --frames 1 --size 32x24)
view(scene_escape_allowed 0 "" ${OUT}/scenes/sub/escape.json --frames 1 --size 32x24 --allow-any-folder)

# --- A texture declaring 16384x16384 in 128 bytes: refused from its header,
# the model renders with its colour.
view(huge_texture 0 "huge_declared.png' declares 16384x16384 pixels, more than the limit"
     ${models}/huge_texture.obj --frames 1 --size 32x24)

# --- Outputs: a FIFO is refused and stays a FIFO; a symbolic link is written
# through and stays a link; --stats-json refuses a device; the stats file
# has one entry per frame, the last holding the lean report.
execute_process(COMMAND ${MKFIFO} ${OUT}/out.fifo)
view(out_fifo 1 "cannot write '${OUT}/out.fifo': not a regular file (a FIFO)"
     ${quad} --frames 1 --size 32x24 --out ${OUT}/out.fifo)
execute_process(COMMAND test -p ${OUT}/out.fifo RESULT_VARIABLE not_fifo)
if(NOT not_fifo EQUAL 0)
  message(FATAL_ERROR "out_fifo: ${OUT}/out.fifo was replaced")
endif()
file(CREATE_LINK ${OUT}/real.png ${OUT}/link.png SYMBOLIC)
view(out_link 0 "" ${quad} --frames 3 --size 32x24 --out ${OUT}/link.png --stats-json ${OUT}/stats.json)
if(NOT IS_SYMLINK ${OUT}/link.png OR NOT EXISTS ${OUT}/real.png)
  message(FATAL_ERROR "out_link: the link was replaced, or its target not written")
endif()
file(READ ${OUT}/stats.json stats)
string(JSON frames LENGTH "${stats}")
if(NOT frames EQUAL 3)
  message(FATAL_ERROR "stats.json: ${frames} entries for 3 frames\n${stats}")
endif()
string(JSON lean_frames GET "${stats}" 2 lean frames)
string(JSON material GET "${stats}" 2 lean materials 0 material)
string(JSON has_lean ERROR_VARIABLE no_lean GET "${stats}" 0 lean)
if(NOT lean_frames EQUAL 3 OR NOT material MATCHES "mtl_quad" OR NOT no_lean)
  message(FATAL_ERROR "stats.json: the last frame should hold the lean report (frames ${lean_frames}, "
                      "material '${material}'), the others not\n${stats}")
endif()
view(stats_device 1 "cannot write the stats file '/dev/full': a device, not a regular file"
     ${quad} --frames 1 --size 32x24 --stats-json /dev/full)

# --- Bad bounds are the model's: nested node scales of 1e38 overflow its
# world bounds; the message says so (not "plane: width must be ..."), exit 2.
view(overflowing_scales 2 "overflowing_scales.gltf: the model cannot be framed: its world bounds are not finite"
     ${models}/overflowing_scales.gltf --frames 1 --size 32x24)

# --- A skinned glTF that crashed assimp, in a scene with other entities:
# everything renders, the skin is drawn in its bind pose.
file(COPY ${models}/skin_no_ibm.gltf DESTINATION ${OUT}/scenes)
file(WRITE ${OUT}/scenes/skinned.json
     "{\"entities\": [{\"name\": \"floor\", \"geometry\": {\"generator\": \"plane\"}},
                      {\"name\": \"skinned\", \"geometry\": {\"model\": \"skin_no_ibm.gltf\"}}]}")
view(skinned_scene 0 "" ${OUT}/scenes/skinned.json --frames 1 --size 32x24)
if(NOT last_out MATCHES "2 entities \\(0 left out\\)")
  message(FATAL_ERROR "skinned_scene: the skinned model should load beside the floor\n${last_out}")
endif()
