# obelisk-mirror with no shaders where it looks (OB_SHADER_DIR names an empty
# folder): the cause, a shader that cannot be read (OB_ERR_IO), reaches the
# message the user reads; it was reported as OB_ERR_OUT_OF_HOST_MEMORY
# because ob_demo_particles returned no error code (issue 25, point 4).
# Run by ctest as: cmake -DBIN=<build>/bin -DOUT=<dir> -P mirror_no_shaders.cmake
cmake_minimum_required(VERSION 3.25)
foreach(var BIN OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "mirror_no_shaders: -D${var}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT}/no-shaders)
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env OB_SHADER_DIR=${OUT}/no-shaders
          ${BIN}/obelisk-mirror --frames 1 --quiet --size 64x48 --out ${OUT}/mirror.png
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
if(rc EQUAL 0)
  message(FATAL_ERROR "obelisk-mirror without shaders exited 0\n${out}\n${err}")
endif()
if(err MATCHES "OUT_OF_HOST_MEMORY" OR NOT err MATCHES "set-up failed: OB_ERR_IO"
   OR NOT err MATCHES "cannot read shader '[a-z_.]+'")
  message(FATAL_ERROR "the message should name the unreadable shader and OB_ERR_IO, not out of memory:\n${err}")
endif()
if(EXISTS ${OUT}/mirror.png)
  message(FATAL_ERROR "an image was written without shaders")
endif()
message(STATUS "ok: ${err}")
