# obelisk-bench --quick: runs, writes JSON/CSV/charts, has every summary
# field with a numeric value, and every threading mode renders the same
# image and commands as single-threaded. Times are never judged.
# Run by ctest as: cmake -DBIN=<build>/bin -DSRC=<src> -DOUT=<dir> -P bench_quick.cmake
cmake_minimum_required(VERSION 3.25)
foreach(var BIN OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "bench_quick: -D${var}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})

# With validation on (ctest sets OB_VALIDATION=1) recording is several times
# slower than the plain --quick run: the timeout leaves room for that.
execute_process(
  COMMAND ${BIN}/obelisk-bench --quick --json ${OUT}/bench.json --csv ${OUT}/bench.csv
          --charts ${OUT}/charts
  RESULT_VARIABLE rc
  OUTPUT_FILE ${OUT}/stdout.txt
  ERROR_FILE ${OUT}/stderr.txt
  TIMEOUT 800)
if(NOT rc EQUAL 0)
  file(READ ${OUT}/stderr.txt err)
  message(FATAL_ERROR "obelisk-bench --quick exited with '${rc}'\n${err}")
endif()

file(READ ${OUT}/bench.json json)
string(JSON summary ERROR_VARIABLE err GET "${json}" summary)
if(err)
  message(FATAL_ERROR "bench.json does not parse or has no summary: ${err}")
endif()

set(number "^-?[0-9]+(\\.[0-9]+)?([eE][-+]?[0-9]+)?$")
foreach(field mt_speedup_record_10k_8views engine_vs_raw_per_draw auto_vs_best_200)
  string(JSON type ERROR_VARIABLE err TYPE "${json}" summary ${field})
  string(JSON value ERROR_VARIABLE err2 GET "${json}" summary ${field})
  if(err OR err2 OR NOT type STREQUAL "NUMBER" OR NOT value MATCHES "${number}" OR value LESS_EQUAL 0)
    message(FATAL_ERROR "summary.${field} is not a positive number: '${value}' (${type}) ${err}")
  endif()
endforeach()
foreach(field name driver)
  string(JSON value ERROR_VARIABLE err GET "${json}" summary device ${field})
  if(err OR value STREQUAL "")
    message(FATAL_ERROR "summary.device.${field} is missing or empty ${err}")
  endif()
endforeach()

# Every threading mode: byte-identical image and equal command hashes.
string(JSON checks LENGTH "${json}" threading_check)
if(checks LESS 1)
  message(FATAL_ERROR "threading_check is empty")
endif()
math(EXPR last "${checks} - 1")
foreach(i RANGE ${last})
  string(JSON mode GET "${json}" threading_check ${i} mode)
  string(JSON diff GET "${json}" threading_check ${i} max_abs_diff)
  string(JSON hashes GET "${json}" threading_check ${i} hash_mismatches)
  if(NOT diff EQUAL 0 OR NOT hashes EQUAL 0)
    message(FATAL_ERROR "mode ${mode}: image error ${diff} (max abs), ${hashes} frames with other command hashes than single-threaded")
  endif()
endforeach()
string(JSON identical GET "${json}" summary threading_identical)
if(NOT identical STREQUAL "ON" AND NOT identical STREQUAL "true")
  message(FATAL_ERROR "summary.threading_identical is '${identical}'")
endif()

# The sweep's frames recorded the same commands in every mode.
string(JSON configs LENGTH "${json}" sweep)
math(EXPR last "${configs} - 1")
foreach(i RANGE ${last})
  string(JSON modes LENGTH "${json}" sweep ${i} modes)
  math(EXPR mlast "${modes} - 1")
  foreach(m RANGE ${mlast})
    string(JSON hashes GET "${json}" sweep ${i} modes ${m} hash_mismatches)
    if(NOT hashes EQUAL 0)
      message(FATAL_ERROR "sweep entry ${i}, mode ${m}: ${hashes} frames with other command hashes")
    endif()
  endforeach()
endforeach()

file(STRINGS ${OUT}/bench.csv csv_lines)
list(LENGTH csv_lines csv_count)
if(csv_count LESS 10)
  message(FATAL_ERROR "bench.csv has only ${csv_count} lines")
endif()
foreach(png speedup.png error.png)
  if(NOT EXISTS ${OUT}/charts/${png})
    message(FATAL_ERROR "chart ${png} was not written")
  endif()
endforeach()
message(STATUS "obelisk-bench --quick: summary ${summary}")
