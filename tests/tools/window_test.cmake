# What the window tests (tests/demo/*_window.cmake) do first, included by
# each: ob_window_test_begin(NAME VAR...) fails when one of the named -D
# variables is missing, and ends the including script with SKIP when the
# build has no window support (-DWINDOW=OFF) or xvfb-run is missing
# (-DXVFB_RUN empty); ./setup.sh installs both (libglfw3-dev, xvfb, xauth).
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
endmacro()
