# ob_run_example(EXE PNG ENV): runs `EXE PNG` with ENV ("" or VAR=value) added
# to the environment; fails unless it exits 0, logs no warning or error and
# PNG is a non-empty PNG file. ob_run_example2(EXE INPUT PNG ENV) runs
# `EXE INPUT PNG` alike.
function(ob_run_example exe png env)
  ob_run_example2(${exe} "" ${png} "${env}")
endfunction()

function(ob_run_example2 exe input png env)
  file(REMOVE ${png})
  set(cmd ${exe} ${input} ${png})
  if(env)
    set(cmd ${CMAKE_COMMAND} -E env ${env} ${cmd})
  endif()
  execute_process(COMMAND ${cmd}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "${exe} ${png}: exit ${code}\n${out}\n${err}")
  endif()
  if(err MATCHES "\\[(warn|error)\\]")
    message(FATAL_ERROR "${exe} logged warnings or errors:\n${err}")
  endif()
  if(NOT EXISTS ${png})
    message(FATAL_ERROR "${exe} wrote no ${png}\n${out}\n${err}")
  endif()
  file(SIZE ${png} size)
  file(READ ${png} magic LIMIT 8 HEX)
  if(size LESS 100 OR NOT magic STREQUAL "89504e470d0a1a0a")
    message(FATAL_ERROR "${png} is not a PNG (${size} bytes, starts ${magic})")
  endif()
  message(STATUS "ok: ${exe} wrote ${png} (${size} bytes)")
endfunction()
