# obelisk-view in a window (GLFW, X11 surface, swapchain) on a virtual X
# server, driven by scripted input (--input feeds the same listener as the
# window's GLFW callbacks), under the validation layer:
#   - an orbit drag, a wheel zoom, wireframe on and off, F1 and a screenshot:
#     exits 0 (3 = the validation layer spoke), every frame presented, the
#     screenshot written where it says, and the final image byte-identical
#     to a headless run of the same script (the window changes nothing in
#     what the controls do);
#   - with the overlay, O switches it to the detailed text.
# Skipped (prints SKIP) without window support or xvfb-run (./setup.sh
# installs libglfw3-dev, xvfb, xauth).
# Run by ctest: cmake -DBIN=... -DSRC=... -DOUT=... -DWINDOW=ON|OFF -DXVFB_RUN=path -P view_window.cmake
include(${CMAKE_CURRENT_LIST_DIR}/../tools/window_test.cmake)
ob_window_test_begin(view_window BIN SRC OUT)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
set(frames 6)
set(scene ${SRC}/demos/scenes/primitives.json)
# Events separated by newlines: a ';' would split a CMake list.
set(script "1:drag left 60 20\n2:wheel 1\n2:key W\n3:key W\n3:key F1\n4:key S")
set(common ${scene} --size 320x200 --frames ${frames} --quiet --threads 2)
set(xvfb ${XVFB_RUN} -a -s "-screen 0 640x480x24")

function(run name)
  ob_window_run(${name} ${ARGN})
  set(last_out "${last_out}" PARENT_SCOPE)
endfunction()

run(window ${xvfb} ${BIN}/obelisk-view ${common} --window --no-overlay --input "${script}"
    --screenshot-prefix ${OUT}/window-shot-)
foreach(line "input: W: wireframe on" "input: W: wireframe off" "input: F1: "
             "screenshot: wrote ${OUT}/window-shot-0001.png \\(320x200\\)")
  if(NOT last_out MATCHES "${line}")
    message(FATAL_ERROR "window: no '${line}' line\n${last_out}")
  endif()
endforeach()
if(NOT EXISTS ${OUT}/window-shot-0001.png)
  message(FATAL_ERROR "window: the screenshot was not written")
endif()
run(headless ${BIN}/obelisk-view ${common} --no-overlay --input "${script}"
    --screenshot-prefix ${OUT}/headless-shot-)
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}/window.png ${OUT}/headless.png
                RESULT_VARIABLE differ)
if(NOT differ EQUAL 0)
  message(FATAL_ERROR "the windowed run's image differs from the headless run of the same script")
endif()

run(overlay ${xvfb} ${BIN}/obelisk-view ${common} --window --input "1:key O")
if(NOT last_out MATCHES "input: O: overlay detailed")
  message(FATAL_ERROR "overlay: O did not switch to the detailed overlay\n${last_out}")
endif()
