# obelisk-mirror in a window (GLFW, X11 surface, swapchain) on a virtual X
# server, under the validation layer with synchronization validation:
#   - switching single/multi-threaded every frame, overlay off: exits 0 (3 =
#     the validation layer spoke), says every frame was presented, and its
#     final image is byte-identical to a headless single-threaded run's;
#   - with the overlay (on by default with --window): exits 0, all presented;
#   - resized from 320x240 to 400x300 by the window system during the run
#     (--window-resize): every frame still presented, the swapchain rebuilt
#     once at the new size, and the final image (the composite's target,
#     which follows the window) is 400x300; the same with --msaa 4 and
#     --exposure 1.5 (the multisampled main view follows the window too);
#   - in every windowed run the swapchain is sRGB (no warning that it is not).
# The renderer presents (ob_renderer_end_frame, same submission as the
# frame); the demo only hands it the window's surface.
# Skipped (prints SKIP) when the build has no window support or xvfb-run is
# missing; ./setup.sh installs both (libglfw3-dev, xvfb, xauth).
# Run by ctest: cmake -DBIN=... -DSRC=... -DOUT=... -DWINDOW=ON|OFF -DXVFB_RUN=path -P mirror_window.cmake
include(${CMAKE_CURRENT_LIST_DIR}/../tools/window_test.cmake)
ob_window_test_begin(mirror_window BIN OUT)
file(MAKE_DIRECTORY ${OUT})
set(frames 6)
set(common --objects 120 --size 320x240 --frames ${frames} --quiet)

function(run name)
  ob_window_run(${name} ${ARGN} ${common})
  set(last_out "${last_out}" PARENT_SCOPE)
endfunction()

# -a: the first free display; the screen is larger than the window.
set(xvfb ${XVFB_RUN} -a -s "-screen 0 640x480x24")

run(window ${xvfb} ${BIN}/obelisk-mirror --window --no-overlay --threads 2 --toggle 1)
run(headless ${BIN}/obelisk-mirror --no-overlay --threads 0)
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${OUT}/window.png ${OUT}/headless.png
                RESULT_VARIABLE same)
if(NOT same EQUAL 0)
  message(FATAL_ERROR "the windowed run's image differs from the headless single-threaded one")
endif()
run(window_overlay ${xvfb} ${BIN}/obelisk-mirror --window --threads 2 --toggle 2)

run(window_resize ${xvfb} ${BIN}/obelisk-mirror --window --no-overlay --threads 2 --toggle 1
    --window-resize 2:400x300)
if(NOT last_out MATCHES "2 swapchains, last 400x300" OR NOT last_out MATCHES "wrote [^\n]* \\(400x300\\)")
  message(FATAL_ERROR "window_resize: the swapchain and the final target did not follow the "
          "window to 400x300\n${last_out}")
endif()

# MSAA and an exposure with a resize: the multisampled main view and its
# resolve target follow the window too, with a silent validation layer.
run(window_resize_msaa ${xvfb} ${BIN}/obelisk-mirror --window --no-overlay --threads 2 --toggle 1
    --msaa 4 --exposure 1.5 --window-resize 3:400x300)
if(NOT last_out MATCHES "2 swapchains, last 400x300" OR NOT last_out MATCHES "wrote [^\n]* \\(400x300\\)")
  message(FATAL_ERROR "window_resize_msaa: the swapchain and the final target did not follow the "
          "window to 400x300\n${last_out}")
endif()
