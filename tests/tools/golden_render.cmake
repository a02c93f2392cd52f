# golden_render.cmake — shared by golden_test.cmake and golden_update.cmake:
# ob_golden_render(INPUT PNG THREADS ARGS...) renders INPUT (relative to SRC
# or absolute) headless with ${BIN}/obelisk-view at 160x120 (unless ARGS
# give --size), --threads THREADS and validation on, into PNG; any failure
# (exit status, an [error] line, a validation message, no image) stops the
# script with obelisk-view's output. Sets OB_GOLDEN_DEVICE to the device's
# name as obelisk-view printed it.

function(ob_golden_input input out_var)
  if(IS_ABSOLUTE ${input})
    set(${out_var} ${input} PARENT_SCOPE)
  else()
    set(${out_var} ${SRC}/${input} PARENT_SCOPE)
  endif()
endfunction()

function(ob_golden_render input png threads)
  set(args ${ARGN})
  if(NOT "--size" IN_LIST args)
    list(APPEND args --size 160x120)
  endif()
  file(REMOVE ${png})
  execute_process(COMMAND ${CMAKE_COMMAND} -E env OB_VALIDATION=1
                          ${BIN}/obelisk-view ${input} --quiet --threads ${threads} ${args} --out ${png}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 600)
  set(cmd "obelisk-view ${input} --threads ${threads} ${args}")
  string(REPLACE ";" " " cmd "${cmd}")
  if(NOT code STREQUAL "0")
    message(FATAL_ERROR "${cmd}: exit ${code}\n${out}\n${err}")
  endif()
  if(err MATCHES "\\[error\\]|did not load|validation: [1-9]")
    message(FATAL_ERROR "${cmd}: errors on a golden input\n${out}\n${err}")
  endif()
  if(NOT EXISTS ${png})
    message(FATAL_ERROR "${cmd}: ${png} was not written\n${out}\n${err}")
  endif()
  # The device obelisk-view ran on ("obelisk-view: INPUT: DEVICE, WxH, mode"),
  # for per-device tolerances (golden_test.cmake).
  if("${out}${err}" MATCHES "obelisk-view: [^\n]*: ([^\n]*), [0-9]+x[0-9]+, [a-z-]+")
    set(OB_GOLDEN_DEVICE "${CMAKE_MATCH_1}" PARENT_SCOPE)
  endif()
endfunction()
