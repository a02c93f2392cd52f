# obelisk-mirror refuses bad options with a message and a non-zero exit, and
# --help succeeds.
execute_process(COMMAND ${BIN}/obelisk-mirror --help RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(NOT rc EQUAL 0 OR NOT out MATCHES "--threads" OR NOT out MATCHES "--no-overlay")
  message(FATAL_ERROR "--help failed or leaves out --no-overlay (${rc}): ${out}")
endif()
# A mistyped option names the one it is closest to; one far from all does not.
execute_process(COMMAND ${BIN}/obelisk-mirror --frmaes 3 RESULT_VARIABLE rc ERROR_VARIABLE err
                OUTPUT_QUIET TIMEOUT 60)
if(rc EQUAL 0 OR NOT err MATCHES "unknown argument '--frmaes' \\(did you mean --frames\\?\\)")
  message(FATAL_ERROR "--frmaes: no suggestion of --frames (exit ${rc}): ${err}")
endif()
execute_process(COMMAND ${BIN}/obelisk-mirror --bogus RESULT_VARIABLE rc ERROR_VARIABLE err
                OUTPUT_QUIET TIMEOUT 60)
if(err MATCHES "did you mean")
  message(FATAL_ERROR "--bogus got a suggestion: ${err}")
endif()
foreach(bad "--frames;0" "--threads;many" "--size;10" "--objects;200000" "--bogus"
            "--malloc-threshold;0" "--malloc-threshold;65536" "--msaa;3" "--msaa;16"
            "--exposure;0" "--exposure;-1" "--exposure;nan" "--exposure;1x")
  execute_process(COMMAND ${BIN}/obelisk-mirror ${bad} RESULT_VARIABLE rc ERROR_VARIABLE err
                  OUTPUT_QUIET TIMEOUT 60)
  if(rc EQUAL 0 OR err STREQUAL "")
    message(FATAL_ERROR "obelisk-mirror ${bad} was accepted (exit ${rc})")
  endif()
endforeach()

# --malloc-threshold (glibc's fixed thresholds, for long runs) is taken and
# the run is otherwise the same: under a sanitizer the allocator refuses it
# and says so, which is not a failure.
execute_process(COMMAND ${BIN}/obelisk-mirror --malloc-threshold 128 --frames 2 --objects 10
                        --threads 2 --toggle 1 --quiet
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
if(NOT rc EQUAL 0 OR NOT out MATCHES "memory: resident")
  message(FATAL_ERROR "obelisk-mirror --malloc-threshold 128 failed (${rc}): ${out}${err}")
endif()

# --msaa 8 on a device that offers fewer samples is lowered with a warning
# naming the view; the run goes on (lavapipe offers 4).
execute_process(COMMAND ${BIN}/obelisk-mirror --msaa 8 --exposure 1.5 --frames 2 --objects 10
                        --threads 2 --toggle 1 --quiet
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "obelisk-mirror --msaa 8 failed (${rc}): ${out}${err}")
endif()
if(err MATCHES "MSAA 8x asked for" AND NOT err MATCHES "view 'main': MSAA 8x asked for; .* using [124]x")
  message(FATAL_ERROR "obelisk-mirror --msaa 8: the lowered count is not said clearly: ${err}")
endif()
