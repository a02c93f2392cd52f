# obelisk-bench with no shaders where it looks (OB_SHADER_DIR names an empty
# folder): it stops before measuring, with exit code 6 and a message naming
# the shader that cannot be read (the material library's creation fails on
# it) and where shaders are looked for, and
# writes no report (before, it ran every configuration on frames that drew
# nothing and reported their times). Its options are parsed first:
# --no-instancing takes no value (it once swallowed the option after it, so
# "--no-instancing --rounds 2" stopped on "unknown option '2'").
# Run by ctest as: cmake -DBIN=<build>/bin -DOUT=<dir> -P bench_no_shaders.cmake
cmake_minimum_required(VERSION 3.25)
foreach(var BIN OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "bench_no_shaders: -D${var}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT}/no-shaders)

execute_process(
  COMMAND ${CMAKE_COMMAND} -E env OB_SHADER_DIR=${OUT}/no-shaders
          ${BIN}/obelisk-bench --quick --no-instancing --rounds 2 --no-progress --json ${OUT}/bench.json
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err
  TIMEOUT 300)
if(NOT rc EQUAL 6)
  message(FATAL_ERROR "obelisk-bench without shaders exited with '${rc}', not 6\n${out}\n${err}")
endif()
if(NOT err MATCHES "cannot be read: OB_ERR_IO"
   OR NOT err MATCHES "obelisk-bench: cannot set up the renderer: OB_ERR_IO"
   OR NOT err MATCHES "OB_SHADER_DIR")
  message(FATAL_ERROR "no clear message naming the effect and the shader folder:\n${err}")
endif()
if(EXISTS ${OUT}/bench.json OR out MATCHES "[0-9]+\\.[0-9]+ ms")
  message(FATAL_ERROR "a report was written without shaders:\n${out}")
endif()
message(STATUS "obelisk-bench stops without shaders: exit 6, ${err}")
