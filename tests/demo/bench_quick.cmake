# obelisk-bench --quick: runs, writes JSON/CSV/charts, has every summary
# field with a numeric value, an MSAA row with a numeric image error and
# frame time per offered sample count, every threading mode renders the same image
# and commands as single-threaded, and every stability case (numerical
# precision, extreme input and load) is reported and within the bound its
# test asserts. Times are never judged.
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
# slower than the plain --quick run: the timeout leaves room for that. One
# warm-up and three idle rounds of two passes instead of --quick's 3, 15 and
# 3: this test checks what the bench writes (two passes are enough to keep
# the faster and check both hashes), never its times, and the sanitizer
# passes run it too. For the same reason its images are small (sweep views
# 64x48 instead of 256x192, quality images 160x120 instead of 640x480):
# lavapipe's rasterising was a third of the run (67 -> 47 s in the plain
# build, and the thread sanitizer's run was CI's longest test at 300 s).
# The charts need gnuplot (./setup.sh installs it); a build carried to a
# machine without it (tests/tools/gpu_pack.sh) checks everything else.
find_program(GNUPLOT gnuplot)
set(charts)
if(GNUPLOT)
  set(charts --charts ${OUT}/charts)
else()
  message(STATUS "gnuplot is not on this machine: the charts are not checked")
endif()
execute_process(
  COMMAND ${BIN}/obelisk-bench --quick --warmup 1 --rounds 3 --passes 2 --view-size 64x48
          --size 160x120 --json ${OUT}/bench.json
          --csv ${OUT}/bench.csv
          ${charts}
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
# The settings say how the figures were taken.
foreach(setting warmup:1 rounds:3 passes:2)
  string(REPLACE ":" ";" kv ${setting})
  list(GET kv 0 key)
  list(GET kv 1 want)
  string(JSON got ERROR_VARIABLE err GET "${json}" settings ${key})
  if(err OR NOT got EQUAL want)
    message(FATAL_ERROR "settings.${key} is '${got}', not ${want} as asked ${err}")
  endif()
endforeach()
# Ratios come with their spread over rounds (_p25, _p75).
set(positive engine_vs_raw_per_draw auto_vs_best_200_frame per_object_growth_50k_vs_1k
    commands_per_object_engine commands_per_object_raw teardown_ns_per_entity_batch
    teardown_ns_per_entity_single)
foreach(field mt_speedup_record_10k_8views engine_vs_raw_per_object auto_vs_best_200
        auto_vs_best_10k_8views)
  list(APPEND positive ${field} ${field}_p25 ${field}_p75)
endforeach()
foreach(field ${positive})
  string(JSON type ERROR_VARIABLE err TYPE "${json}" summary ${field})
  string(JSON value ERROR_VARIABLE err2 GET "${json}" summary ${field})
  if(err OR err2 OR NOT type STREQUAL "NUMBER" OR NOT value MATCHES "${number}" OR value LESS_EQUAL 0)
    message(FATAL_ERROR "summary.${field} is not a positive number: '${value}' (${type}) ${err}")
  endif()
endforeach()
# The whole frame's CPU phases (update included) and their serial share, the
# per-object pre-render and update costs: each a number, or null where the
# run could not compute it.
set(frame_fields amdahl_speedup_16_cores gpu_ms_10k_8views gpu_ms_10k_8views_per_draw
    gpu_time_instanced_vs_per_draw_10k_8views raw_gpu_ms raw_gpu_instanced_ms)
foreach(field frame_cpu_speedup_10k_8views serial_fraction_10k_8views prerender_ns_per_object_view
        update_ns_per_object raw_gpu_instanced_vs_per_draw)
  list(APPEND frame_fields ${field} ${field}_p25 ${field}_p75)
endforeach()
foreach(field ${frame_fields})
  string(JSON type ERROR_VARIABLE err TYPE "${json}" summary ${field})
  string(JSON value ERROR_VARIABLE err2 GET "${json}" summary ${field})
  if(err OR NOT (type STREQUAL "NULL" OR (type STREQUAL "NUMBER" AND value MATCHES "${number}")))
    message(FATAL_ERROR "summary.${field} is missing or not a number: '${value}' (${type}) ${err}")
  endif()
endforeach()
# Where the device has timestamps (the engine's frame has a GPU time), the
# raw loops were executed and timed too: their times are positive numbers.
string(JSON type TYPE "${json}" summary gpu_ms_10k_8views)
if(type STREQUAL "NUMBER")
  foreach(field raw_gpu_ms raw_gpu_instanced_ms raw_gpu_instanced_vs_per_draw)
    string(JSON type ERROR_VARIABLE err TYPE "${json}" summary ${field})
    string(JSON value ERROR_VARIABLE err GET "${json}" summary ${field})
    if(err OR NOT type STREQUAL "NUMBER" OR value LESS_EQUAL 0)
      message(FATAL_ERROR "summary.${field} is '${value}' (${type}): the raw loops were not timed "
                          "on a device with timestamps")
    endif()
  endforeach()
endif()
# Spreads in order (p25 <= median <= p75) wherever all three are numbers.
foreach(spread mt_speedup_record_10k_8views engine_vs_raw_per_object auto_vs_best_200
        auto_vs_best_10k_8views frame_cpu_speedup_10k_8views serial_fraction_10k_8views
        prerender_ns_per_object_view update_ns_per_object raw_gpu_instanced_vs_per_draw)
  string(JSON t_lo TYPE "${json}" summary ${spread}_p25)
  string(JSON t_mid TYPE "${json}" summary ${spread})
  string(JSON t_hi TYPE "${json}" summary ${spread}_p75)
  if(NOT t_lo STREQUAL "NUMBER" OR NOT t_mid STREQUAL "NUMBER" OR NOT t_hi STREQUAL "NUMBER")
    continue()
  endif()
  string(JSON lo GET "${json}" summary ${spread}_p25)
  string(JSON mid GET "${json}" summary ${spread})
  string(JSON hi GET "${json}" summary ${spread}_p75)
  if(lo GREATER mid OR mid GREATER hi)
    message(FATAL_ERROR "summary.${spread}: p25 ${lo}, median ${mid}, p75 ${hi} are out of order")
  endif()
endforeach()
# The lights section: two rows (grid, every light) per light count, each
# with a positive cost, and the growth exponents in the summary.
string(JSON light_rows ERROR_VARIABLE err LENGTH "${json}" lights rows)
if(err OR NOT light_rows EQUAL 10)
  message(FATAL_ERROR "lights.rows has '${light_rows}' rows, not 10 (5 counts x grid/all) ${err}")
endif()
math(EXPR last "${light_rows} - 1")
foreach(i RANGE ${last})
  string(JSON cost ERROR_VARIABLE err GET "${json}" lights rows ${i} cost_ms)
  if(err OR NOT cost MATCHES "${number}" OR cost LESS_EQUAL 0)
    message(FATAL_ERROR "lights.rows[${i}].cost_ms is not a positive number: '${cost}' ${err}")
  endif()
endforeach()
foreach(field lights_cost_exponent_4_to_256 lights_cost_exponent_4_to_256_all)
  string(JSON value ERROR_VARIABLE err GET "${json}" summary ${field})
  if(err OR NOT value MATCHES "${number}")
    message(FATAL_ERROR "summary.${field} is not a number: '${value}' ${err}")
  endif()
endforeach()
# The distance between the first two CPUs (a cache line's round trip), at
# the run's start and end: every MT figure follows it on a VM.
string(JSON cores GET "${json}" machine cores)
foreach(i 0 1)
  string(JSON type ERROR_VARIABLE err TYPE "${json}" machine core_to_core_round_trip_ns ${i})
  if(err OR NOT (type STREQUAL "NUMBER" OR (cores LESS 2 AND type STREQUAL "NULL")))
    message(FATAL_ERROR "machine.core_to_core_round_trip_ns[${i}] is ${type} on ${cores} cores ${err}")
  endif()
  if(type STREQUAL "NUMBER")
    string(JSON value GET "${json}" machine core_to_core_round_trip_ns ${i})
    if(NOT value GREATER 0)
      message(FATAL_ERROR "machine.core_to_core_round_trip_ns[${i}] is ${value}")
    endif()
  endif()
endforeach()
string(JSON type ERROR_VARIABLE err TYPE "${json}" summary frame_cpu_mode)
if(err OR NOT type STREQUAL "STRING")
  message(FATAL_ERROR "summary.frame_cpu_mode is missing or not a string: ${type} ${err}")
endif()
# Host allocations: the raw loop counts its own (a driver may make none); the
# engine's are null until the recording path reports them.
foreach(field host_allocs_per_object_raw host_allocs_per_object_engine)
  string(JSON type ERROR_VARIABLE err TYPE "${json}" summary ${field})
  if(err OR NOT (type STREQUAL "NUMBER" OR type STREQUAL "NULL"))
    message(FATAL_ERROR "summary.${field} is missing or not a number: ${type} ${err}")
  endif()
endforeach()
string(JSON type TYPE "${json}" summary host_allocs_per_object_raw)
if(NOT type STREQUAL "NUMBER")
  message(FATAL_ERROR "summary.host_allocs_per_object_raw is ${type}: the raw loop counts them itself")
endif()
# Per mode: the speedup's spread and the recording CPU times (null until the
# engine reports them) sit next to the wall times.
foreach(field speedup_record_p25 speedup_record_p75 vs_best_fixed_record record_cpu_render_ms
        record_cpu_workers_ms record_cpu_max_worker_ms cmd_host_allocs_per_object
        commands_per_object update_cpu_ms frame_cpu_speedup frame_cpu_speedup_p25
        frame_cpu_speedup_p75 serial_fraction serial_fraction_p25 serial_fraction_p75
        gpu_views_ms upload_mb gpu_flight_ms gpu_rest_ms)
  string(JSON type ERROR_VARIABLE err TYPE "${json}" sweep 0 modes 0 ${field})
  if(err OR NOT (type STREQUAL "NUMBER" OR type STREQUAL "NULL"))
    message(FATAL_ERROR "sweep[0].modes[0].${field} is missing: ${type} ${err}")
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

# MSAA rows of the quality section: one antialiasing reference (drawn larger
# with the most samples the device offers, box-downsampled) and a row per
# offered sample count, 1x first, each with a numeric image error and frame
# time; no row has more samples than the reference.
string(JSON qrows LENGTH "${json}" quality)
math(EXPR last "${qrows} - 1")
set(msaa_ref 0)
set(msaa_counts "")
foreach(i RANGE ${last})
  string(JSON kind GET "${json}" quality ${i} kind)
  if(kind STREQUAL "msaa-reference")
    math(EXPR msaa_ref "${msaa_ref} + 1")
    string(JSON ref_samples GET "${json}" quality ${i} msaa_samples)
    string(JSON ref_scale GET "${json}" quality ${i} supersample)
    string(JSON ref_text GET "${json}" quality ${i} reference)
    if(NOT ref_scale GREATER 1 OR NOT ref_samples GREATER 0 OR ref_text STREQUAL "")
      message(FATAL_ERROR "msaa-reference row: supersample ${ref_scale}, msaa_samples ${ref_samples}, reference '${ref_text}'")
    endif()
  elseif(kind STREQUAL "msaa")
    string(JSON samples GET "${json}" quality ${i} msaa_samples)
    list(APPEND msaa_counts ${samples})
    string(JSON msaa_psnr_${samples} GET "${json}" quality ${i} psnr_db)
    foreach(field max_abs_diff psnr_db frame_ms)
      string(JSON type ERROR_VARIABLE err TYPE "${json}" quality ${i} ${field})
      string(JSON value ERROR_VARIABLE err2 GET "${json}" quality ${i} ${field})
      if(err OR err2 OR NOT type STREQUAL "NUMBER" OR NOT value MATCHES "${number}")
        message(FATAL_ERROR "quality row ${i} (msaa ${samples}x): ${field} is not a number: '${value}' (${type}) ${err}")
      endif()
    endforeach()
    string(JSON against GET "${json}" quality ${i} against)
    if(NOT against STREQUAL "msaa-reference")
      message(FATAL_ERROR "quality row ${i} (msaa ${samples}x) is measured against '${against}'")
    endif()
  endif()
endforeach()
# The cube series (issue 28): its reference at the largest env-map size,
# measured against the paraboloid reference, and a smaller size measured
# against it, each with a numeric error and frame time.
set(cube_ref 0)
set(cube_rows 0)
foreach(i RANGE ${last})
  string(JSON kind GET "${json}" quality ${i} kind)
  if(kind STREQUAL "env-cube-reference" OR kind STREQUAL "env-cube")
    if(kind STREQUAL "env-cube")
      math(EXPR cube_rows "${cube_rows} + 1")
      string(JSON against GET "${json}" quality ${i} against)
      if(NOT against STREQUAL "env-cube-reference")
        message(FATAL_ERROR "quality row ${i} (env-cube) is measured against '${against}'")
      endif()
    else()
      math(EXPR cube_ref "${cube_ref} + 1")
    endif()
    foreach(field psnr_db frame_ms)
      string(JSON type ERROR_VARIABLE err TYPE "${json}" quality ${i} ${field})
      if(NOT type STREQUAL "NUMBER")
        message(FATAL_ERROR "quality row ${i} (${kind}): ${field} is not a number (${type})")
      endif()
    endforeach()
  endif()
endforeach()
if(NOT cube_ref EQUAL 1 OR cube_rows LESS 1)
  message(FATAL_ERROR "quality has ${cube_ref} env-cube-reference and ${cube_rows} env-cube rows, expected 1 and at least 1")
endif()
if(NOT msaa_ref EQUAL 1)
  message(FATAL_ERROR "quality has ${msaa_ref} msaa-reference rows, expected 1")
endif()
list(LENGTH msaa_counts n_msaa)
list(GET msaa_counts 0 first_count)
if(n_msaa LESS 1 OR NOT first_count EQUAL 1)
  message(FATAL_ERROR "MSAA rows for sample counts '${msaa_counts}': expected 1x first")
endif()
if(ref_samples GREATER 1 AND n_msaa LESS 2)
  message(FATAL_ERROR "the device offers ${ref_samples}x but only '${msaa_counts}' were measured")
endif()
foreach(samples ${msaa_counts})
  if(samples GREATER ref_samples)
    message(FATAL_ERROR "an MSAA row has ${samples}x, more than its reference's ${ref_samples}x")
  endif()
endforeach()
# Image error, not time: the most samples measured come closer to the
# antialiasing reference than one sample does (lavapipe: 4x by some 5 dB).
list(GET msaa_counts -1 most)
if(most GREATER 1 AND NOT msaa_psnr_${most} GREATER msaa_psnr_1)
  message(FATAL_ERROR "MSAA ${most}x: PSNR ${msaa_psnr_${most}} dB against the reference, not above 1x's ${msaa_psnr_1} dB")
endif()
file(STRINGS ${OUT}/bench.csv msaa_csv REGEX "^msaa,")
list(LENGTH msaa_csv n_csv)
if(NOT n_csv EQUAL n_msaa)
  message(FATAL_ERROR "bench.csv has ${n_csv} msaa rows, the JSON ${n_msaa}")
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

# Stability: every case family reported, each row with a numeric error, a
# unit, and pass = true, or measured only (verdict "measured", pass null: a
# row without a bound neither passes nor fails); a row over its bound also
# makes the program exit 5.
string(JSON rows ERROR_VARIABLE err LENGTH "${json}" stability)
if(err OR rows LESS 40)
  message(FATAL_ERROR "stability has ${rows} rows (expected 40 or more) ${err}")
endif()
set(names "")
set(measured 0)
math(EXPR last "${rows} - 1")
foreach(i RANGE ${last})
  string(JSON name GET "${json}" stability ${i} name)
  string(JSON pass GET "${json}" stability ${i} pass)
  string(JSON etype TYPE "${json}" stability ${i} error)
  string(JSON unit GET "${json}" stability ${i} unit)
  string(JSON measure GET "${json}" stability ${i} measure)
  if(NOT etype STREQUAL "NUMBER" OR unit STREQUAL "" OR measure STREQUAL "")
    message(FATAL_ERROR "stability row '${name}': error is ${etype}, unit '${unit}', measure '${measure}'")
  endif()
  string(JSON verdict GET "${json}" stability ${i} verdict)
  string(JSON ptype TYPE "${json}" stability ${i} pass)
  string(JSON btype TYPE "${json}" stability ${i} bound)
  if(verdict STREQUAL "measured")
    if(NOT ptype STREQUAL "NULL" OR NOT btype STREQUAL "NULL")
      message(FATAL_ERROR "stability row '${name}' is measured only but has pass ${ptype}, bound ${btype}")
    endif()
    math(EXPR measured "${measured} + 1")
  elseif(NOT verdict STREQUAL "pass" OR (NOT pass STREQUAL "ON" AND NOT pass STREQUAL "true"))
    string(JSON error GET "${json}" stability ${i} error)
    string(JSON detail GET "${json}" stability ${i} detail)
    message(FATAL_ERROR "stability row '${name}' failed: error ${error} ${unit} (${detail})")
  endif()
  list(APPEND names "${name}")
endforeach()
foreach(family depth_precision depth_resolution "large_coordinates 1e7" "large_coordinates 1e11"
        "large_coordinates matrices" scale_invariance "deep_hierarchy 10000" "deep_hierarchy 100000"
        long_run_rotation zero_scale flattened_box up_parallel_to_direction
        refused_views_and_cameras empty_scene light_intensity_0 non_finite_transform
        non_finite_light non_finite_camera non_finite_material non_finite_parameter
        beyond_float_range views_64 view_cap_128 env_recursion objects_ shadow_map_no_casters)
  string(FIND "${names}" "${family}" at)
  if(at LESS 0)
    message(FATAL_ERROR "no stability row for '${family}'")
  endif()
endforeach()
string(JSON failed GET "${json}" stability_info failed)
string(JSON validation GET "${json}" stability_info validation)
string(JSON info_measured GET "${json}" stability_info measured_only)
if(NOT info_measured EQUAL measured OR measured LESS 1)
  message(FATAL_ERROR "stability_info.measured_only is ${info_measured}, the rows say ${measured} (some rows are measured only)")
endif()
if(NOT failed EQUAL 0)
  message(FATAL_ERROR "stability_info.failed is ${failed}")
endif()
if((validation STREQUAL "ON" OR validation STREQUAL "true") AND NOT "${names}" MATCHES "validation_layer")
  message(FATAL_ERROR "validation was on but there is no validation_layer row")
endif()
file(STRINGS ${OUT}/bench-stability.csv stability_lines)
list(LENGTH stability_lines stability_count)
math(EXPR want "${rows} + 1")
if(NOT stability_count EQUAL want)
  message(FATAL_ERROR "bench-stability.csv has ${stability_count} lines, expected ${want}")
endif()

file(STRINGS ${OUT}/bench.csv csv_lines)
list(LENGTH csv_lines csv_count)
if(csv_count LESS 10)
  message(FATAL_ERROR "bench.csv has only ${csv_count} lines")
endif()
# Every row has as many columns as the header, which names the frame columns.
list(GET csv_lines 0 csv_header)
foreach(column frame_cpu_speedup serial_fraction prerender_ns_per_object_view
        update_ns_per_object update_cpu_ms)
  if(NOT ",${csv_header}," MATCHES ",${column},")
    message(FATAL_ERROR "bench.csv has no column ${column}")
  endif()
endforeach()
string(REGEX REPLACE "[^,]" "" header_commas "${csv_header}")
foreach(line ${csv_lines})
  string(REGEX REPLACE "[^,]" "" line_commas "${line}")
  if(NOT line_commas STREQUAL header_commas)
    message(FATAL_ERROR "bench.csv row '${line}' has another column count than the header")
  endif()
endforeach()
foreach(png speedup.png error.png)
  if(GNUPLOT AND NOT EXISTS ${OUT}/charts/${png})
    message(FATAL_ERROR "chart ${png} was not written")
  endif()
endforeach()
message(STATUS "obelisk-bench --quick: summary ${summary}; ${rows} stability rows, all within their bounds but ${measured} measured only")
