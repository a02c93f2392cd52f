# fuzz/model_run.cmake — the model loader's fuzz runs, in two modes.
#
# MODE=replay (what CI runs: the fuzz_model ctest entry, fuzz/model.cmake):
# every input of the SEEDS folders (the seeds, the saved findings in
# fuzz/corpus/model-findings and the known assimp inputs) is run once, alone,
# and triaged as below. No random search: the same commit always gives the
# same verdict, in seconds.
#
#   cmake -DMODE=replay -DFUZZER=build-fuzz/bin/fuzz_model \
#         "-DSEEDS=fuzz/corpus/model;fuzz/corpus/model-findings;fuzz/corpus/model-assimp-known" \
#         -P fuzz/model_run.cmake
#
# MODE=explore (by hand, outside CI; `./setup.sh fuzz-explore`): a bounded
# fork-mode libFuzzer session from the seeds, then the same triage of
# everything it saved. A finding in our code fails the run; fix it and add
# the input to fuzz/corpus/model-findings, where CI replays it from then on.
#
#   cmake -DMODE=explore -DFUZZER=build-fuzz/bin/fuzz_model -DWORK=/tmp/corpus \
#         "-DSEEDS=fuzz/corpus/model" -DARTIFACTS=/tmp/artifacts [-DSECONDS=600] \
#         -P fuzz/model_run.cmake
#
# Debian's libassimp (not instrumented, asserts on) crashes, hangs or asks
# for absurd amounts of memory on some inputs inside aiImportFile, before
# our loader sees any data. Plain libFuzzer stops at the first such input,
# so exploration runs in fork mode and keeps going past crashes, timeouts
# and OOMs, saving each input. Every input triaged is run alone and
# classified by the first frame of its report that is not a sanitizer,
# libc, libstdc++ or libFuzzer frame:
#   assimp — inside libassimp.so: listed (see docs/soak.md), not a failure;
#   ours   — in our code (or no assimp frame at all): the run fails;
#   clean  — no report (replay) / gone: did not happen again alone (explore).
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED MODE)
  set(MODE explore)
endif()
set(required FUZZER SEEDS)
if(MODE STREQUAL "explore")
  list(APPEND required WORK ARTIFACTS)
elseif(NOT MODE STREQUAL "replay")
  message(FATAL_ERROR "model_run.cmake: MODE must be replay or explore, not '${MODE}'")
endif()
foreach(var ${required})
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "model_run.cmake (MODE=${MODE}) needs -D${var}=...")
  endif()
endforeach()
if(NOT DEFINED SECONDS)
  set(SECONDS 60)
endif()

if(MODE STREQUAL "replay")
  set(findings "")
  foreach(dir ${SEEDS})
    file(GLOB inputs LIST_DIRECTORIES false ${dir}/*)
    list(APPEND findings ${inputs})
  endforeach()
  list(SORT findings)
  list(LENGTH findings n)
  if(n EQUAL 0)
    message(FATAL_ERROR "fuzz_model replay: no inputs in ${SEEDS}")
  endif()
  message(STATUS "fuzz_model: replaying ${n} saved inputs, each once")
else()
  file(REMOVE_RECURSE ${ARTIFACTS})
  file(MAKE_DIRECTORY ${ARTIFACTS} ${WORK})
  execute_process(
    COMMAND ${FUZZER} -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1
            -max_total_time=${SECONDS} -timeout=5 -rss_limit_mb=2048
            -artifact_prefix=${ARTIFACTS}/ ${WORK} ${SEEDS}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  set(log "${out}${err}")
  # Fork mode reports "#<execs>: cov: <n> ft: <n> corp: <n> exec/s <n> oom/timeout/crash: a/b/c time: ..."
  string(REGEX MATCHALL "#[0-9]+: cov: [0-9]+ ft: [0-9]+ corp: [0-9]+[^\n]*" progress "${log}")
  list(LENGTH progress n)
  if(n EQUAL 0)
    message(FATAL_ERROR "fuzz_model printed no progress (exit ${rc}):\n${log}")
  endif()
  list(GET progress -1 last)
  message(STATUS "fuzz_model, ${SECONDS} s in fork mode: ${last}")
  file(GLOB findings ${ARTIFACTS}/crash-* ${ARTIFACTS}/timeout-* ${ARTIFACTS}/oom-* ${ARTIFACTS}/leak-*
       ${ARTIFACTS}/slow-unit-*)
endif()

set(ours "")
set(assimp_count 0)
set(gone_count 0)
set(signatures "")
foreach(input ${findings})
  get_filename_component(name ${input} NAME)
  execute_process(COMMAND ${FUZZER} -timeout=5 -rss_limit_mb=2048 ${input}
                  RESULT_VARIABLE again OUTPUT_VARIABLE o ERROR_VARIABLE e TIMEOUT 60)
  set(report "${o}${e}")
  string(REGEX MATCH "(ERROR: [A-Za-z]+: [A-Za-z-]+|runtime error: [^\n]*)" what "${report}")
  if(again EQUAL 0 AND NOT what)
    math(EXPR gone_count "${gone_count} + 1")
    if(MODE STREQUAL "explore")
      list(APPEND signatures "gone: ${name}")
    endif()
    continue()
  endif()
  string(REGEX MATCHALL "\n +#[0-9]+ 0x[0-9a-f]+ [^\n]*" frames "${report}")
  set(first "")
  foreach(frame ${frames})
    # Runtime frames: sanitizers and their libc interceptors, libc,
    # libstdc++, libgcc, libFuzzer.
    if(frame MATCHES "libc\\.so|libc-|libm\\.so|libstdc\\+\\+|libgcc|__sanitizer|__asan|__ubsan|__lsan|__interceptor|fuzzer::|operator new|operator delete|__assert|__libc_|sysdeps/|libio/|string/|nptl/|stdlib/|/io/| in _start| in main \\(")
      continue()
    endif()
    if(frame MATCHES " in (malloc|calloc|realloc|free|abort|raise|pthread_kill|str[a-z]*|mem[a-z]*|[a-z]*printf|[a-z]*scanf|f?read|f?write|f?seek[a-z0-9]*|ftell|fopen|fclose|lseek[0-9]*) ")
      continue()
    endif()
    set(first "${frame}")
    break()
  endforeach()
  string(STRIP "${first}" first)
  if(first MATCHES "libassimp\\.so[^ ]*\\+(0x[0-9a-f]+)")
    math(EXPR assimp_count "${assimp_count} + 1")
    string(REGEX MATCH "\\(([^)]*libassimp[^)]*)\\)" where "${first}")
    list(APPEND signatures "assimp: ${what} at ${CMAKE_MATCH_1}")
  else()
    list(APPEND ours "${name}: ${what}\n  first frame: ${first}")
  endif()
endforeach()
list(LENGTH findings total)
list(REMOVE_DUPLICATES signatures)
string(REPLACE ";" "\n  " listed "${signatures}")
if(MODE STREQUAL "replay")
  math(EXPR clean "${total} - ${assimp_count}")
  list(LENGTH ours ours_count)
  math(EXPR clean "${clean} - ${ours_count}")
  message(STATUS "${total} inputs replayed: ${clean} clean, ${assimp_count} inside assimp (known)"
          "\n  ${listed}")
else()
  message(STATUS "${total} inputs saved: ${assimp_count} inside assimp, ${gone_count} not reproduced alone"
          "\n  ${listed}")
endif()
if(ours)
  string(REPLACE ";" "\n" listed_ours "${ours}")
  message(FATAL_ERROR "findings in our code:\n${listed_ours}")
endif()
