# obelisk-mirror refuses bad options with a message and a non-zero exit, and
# --help succeeds.
execute_process(COMMAND ${BIN}/obelisk-mirror --help RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "--threads")
  message(FATAL_ERROR "--help failed (${rc}): ${out}")
endif()
foreach(bad "--frames;0" "--threads;many" "--size;10" "--objects;200000" "--bogus")
  execute_process(COMMAND ${BIN}/obelisk-mirror ${bad} RESULT_VARIABLE rc ERROR_VARIABLE err
                  OUTPUT_QUIET TIMEOUT 60)
  if(rc EQUAL 0 OR err STREQUAL "")
    message(FATAL_ERROR "obelisk-mirror ${bad} was accepted (exit ${rc})")
  endif()
endforeach()
