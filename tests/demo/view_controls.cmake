# obelisk-view's controls, driven headless through --input (the same
# listener the window's GLFW callbacks feed), on demos/scenes/primitives.json
# at 320x200, under the validation layer:
#   - input that moves nothing (a key the viewer ignores, the overlay key
#     without an overlay) leaves the image and every frame's command hash
#     exactly as a run without --input;
#   - an orbit drag, a pan drag and a wheel zoom each change the image; the
#     script read from a file (--input @FILE) does what it does inline;
#   - S writes the numbered screenshot, prints its path, and the PNG is the
#     frame (same size as --out);
#   - W draws wireframe (another image), W again restores the filled image
#     and hashes exactly;
#   - F frames the scene (says so), R reloads the file (says so);
#   - a reload of a file that no longer parses keeps the scene on screen:
#     the error is printed, the run exits 0 and its image is the one a run
#     without the reload gives. (The file is a symbolic link to the path S
#     writes its first screenshot to, so the scene file turns into a PNG at
#     a known frame.)
#   - a mistyped script is refused (exit 2) naming the event.
# (Events are separated by newlines here: a ';' would split a CMake list.)
# Run by ctest: cmake -DBIN=<build>/bin -DSRC=<source> -DOUT=<dir> -P view_controls.cmake
foreach(var BIN SRC OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "view_controls: -D${var}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
set(scene ${SRC}/demos/scenes/primitives.json)
set(common --frames 5 --size 320x200 --quiet)

# view(NAME SCENE args...): runs obelisk-view headless, out image NAME.png and
# stats NAME.json in OUT; its stdout in view_out.
function(view name input)
  execute_process(COMMAND ${BIN}/obelisk-view ${input} ${common} --out ${OUT}/${name}.png
                          --stats-json ${OUT}/${name}.json ${ARGN}
                  WORKING_DIRECTORY ${OUT}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
  if(NOT code STREQUAL "0")
    message(FATAL_ERROR "${name}: exit ${code}\n${out}\n${err}")
  endif()
  if(err MATCHES "\\[error\\]")
    message(FATAL_ERROR "${name}: errors in the log\n${err}")
  endif()
  set(view_out "${out}" PARENT_SCOPE)
endfunction()

function(hashes name outvar)
  file(READ ${OUT}/${name}.json json)
  string(JSON n LENGTH "${json}")
  math(EXPR last "${n} - 1")
  set(list "")
  foreach(i RANGE ${last})
    string(JSON h GET "${json}" ${i} frame_hash)
    list(APPEND list ${h})
  endforeach()
  set(${outvar} "${list}" PARENT_SCOPE)
endfunction()

function(same a b why)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}/${a}.png ${OUT}/${b}.png
                  RESULT_VARIABLE differ)
  if(NOT differ EQUAL 0)
    message(FATAL_ERROR "${a}.png differs from ${b}.png: ${why}")
  endif()
endfunction()

function(differs a b why)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}/${a}.png ${OUT}/${b}.png
                  RESULT_VARIABLE differ)
  if(differ EQUAL 0)
    message(FATAL_ERROR "${a}.png is ${b}.png: ${why}")
  endif()
endfunction()

# says(WHAT REGEX): the last run's stdout has a line matching REGEX.
function(says what regex)
  if(NOT view_out MATCHES "${regex}")
    message(FATAL_ERROR "${what}: no line matching '${regex}'\n${view_out}")
  endif()
endfunction()

view(base ${scene})
hashes(base base_hashes)

# Input that moves nothing changes nothing.
view(idle ${scene} --input "1:key Q\n2:key O\n3:key shift+W")
same(idle base "input that moves nothing changed the image")
hashes(idle idle_hashes)
if(NOT idle_hashes STREQUAL base_hashes)
  message(FATAL_ERROR "input that moves nothing changed the command hashes:\n ${base_hashes}\n ${idle_hashes}")
endif()

view(orbit ${scene} --input "1:drag left 80 30")
differs(orbit base "an orbit drag did not move the camera")
# The same script from a file (--input @FILE), with a comment.
file(WRITE ${OUT}/orbit.input "# orbit once\n1:drag left 80 30\n")
view(orbit_file ${scene} --input @${OUT}/orbit.input)
same(orbit_file orbit "--input @FILE did not play the same events")
view(pan ${scene} --input "1:drag middle 40 0")
differs(pan base "a pan drag did not move the camera")
differs(pan orbit "pan and orbit gave the same image")
view(pan_shift ${scene} --input "1:drag shift+left 40 0")
same(pan_shift pan "shift + left drag is not the same pan as a middle drag")
view(zoom ${scene} --input "1:wheel 3")
differs(zoom base "the wheel did not zoom")

# Screenshot: numbered, path printed, the frame itself.
view(shot ${scene} --input "4:key S" --screenshot-prefix ${OUT}/shot-)
says("S" "screenshot: wrote ${OUT}/shot-0001.png \\(320x200\\)")
if(NOT EXISTS ${OUT}/shot-0001.png)
  message(FATAL_ERROR "S: ${OUT}/shot-0001.png was not written")
endif()
file(RENAME ${OUT}/shot-0001.png ${OUT}/shot_frame4.png)
same(shot_frame4 base "the screenshot after the last frame is not the final image")

# Wireframe on: another image and other hashes; on and off again: exactly the filled run.
view(wire ${scene} --input "1:key W")
says("W" "input: W: wireframe on")
differs(wire base "wireframe draws the same image as filled")
view(wire_off ${scene} --input "1:key W\n2:key W")
same(wire_off base "wireframe off again did not restore the filled image")
hashes(wire_off wire_off_hashes)
list(GET wire_off_hashes 4 last_off)
list(GET base_hashes 4 last_base)
if(NOT last_off STREQUAL last_base)
  message(FATAL_ERROR "wireframe off again: the last frame's hash ${last_off} is not ${last_base}")
endif()

# F frames the scene; R reloads it.
view(frame_all ${scene} --input "1:drag left 200 0\n2:key F")
says("F" "input: F: framed the scene")
differs(frame_all base "F did not frame the scene")
view(reload ${scene} --input "2:key R")
says("R" "obelisk-view: reloaded [^\n]*primitives.json: 17 entities")

# A reload of a file that stopped parsing keeps the scene.
file(COPY ${scene} DESTINATION ${OUT}/broken)
file(RENAME ${OUT}/broken/primitives.json ${OUT}/broken/snap-0001.png)
file(CREATE_LINK snap-0001.png ${OUT}/broken/scene.json SYMBOLIC)
view(broken ${OUT}/broken/scene.json --input "2:key S\n3:key R" --screenshot-prefix ${OUT}/broken/snap-)
says("broken reload" "obelisk-view: reload: [^\n]*scene.json")
says("broken reload" "keeping the scene on screen")
same(broken base "a broken reload changed what is on screen")

execute_process(COMMAND ${BIN}/obelisk-view ${scene} ${common} --input "1:drag up 1 1"
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
if(NOT code STREQUAL "2" OR NOT err MATCHES "unknown button 'up'")
  message(FATAL_ERROR "a bad --input was not refused with the event (exit ${code})\n${err}")
endif()
