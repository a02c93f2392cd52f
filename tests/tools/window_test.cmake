# What the window tests (tests/demo/*_window.cmake) do first, included by
# each: ob_window_test_begin(NAME VAR...) fails when one of the named -D
# variables is missing, and ends the including script with SKIP when the
# build has no window support (-DWINDOW=OFF) or xvfb-run is missing
# (-DXVFB_RUN empty, or a path this machine lacks); ./setup.sh installs both (libglfw3-dev, xvfb, xauth).
# A macro, so that its return() ends the test script itself.
macro(ob_window_test_begin name)
  foreach(var ${ARGN})
    if(NOT DEFINED ${var})
      message(FATAL_ERROR "${name}: -D${var}=... is required")
    endif()
  endforeach()
  if(NOT WINDOW)
    message("SKIP: this build has no window support (configure with GLFW: libglfw3-dev)")
    return()
  endif()
  if(NOT XVFB_RUN)
    message("SKIP: xvfb-run not found (Debian: xvfb xauth)")
    return()
  endif()
  # The path found at configure time, gone on this machine (a build carried
  # to a GPU machine by tests/tools/gpu_pack.sh, which has no X server).
  if(NOT EXISTS "${XVFB_RUN}")
    message("SKIP: ${XVFB_RUN} is not on this machine (Debian: xvfb xauth)")
    return()
  endif()
endmacro()

# ob_window_run(NAME COMMAND...): runs COMMAND --out OUT/NAME.png (as the
# including script's `run` does, its arguments already complete) and fails
# when it exits non-zero, when a windowed run's swapchain is not sRGB (the
# window then shows other colours than the PNG holds), when the validation
# layer spoke, or when a run with --window did not present all ${frames}
# frames. Its stdout goes to last_out in the caller's scope.
function(ob_window_run name)
  execute_process(COMMAND ${ARGN} --out ${OUT}/${name}.png
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
  set(last_out "${out}" PARENT_SCOPE)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name}: exited with ${rc}\n${out}\n${err}")
  endif()
  if(err MATCHES "offers no B8G8R8A8/R8G8B8A8 sRGB format")
    message(FATAL_ERROR "${name}: the swapchain is not sRGB\n${err}")
  endif()
  if(NOT out MATCHES "validation: 0 errors, 0 warnings")
    message(FATAL_ERROR "${name}: the run did not report a silent validation layer\n${out}")
  endif()
  if("${ARGN}" MATCHES "--window" AND NOT out MATCHES "window: ${frames} frames presented, 0 skipped")
    message(FATAL_ERROR "${name}: not every frame was presented\n${out}")
  endif()
endfunction()
