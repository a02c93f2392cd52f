# fuzz/model.cmake — the libFuzzer target for the model loader (fuzz_model)
# and its bounded ctest run, included from fuzz/CMakeLists.txt (which the
# top level adds when OB_FUZZ is ON). Needs clang. The loader and what it uses (engine/ob_core.c,
# geometry/ob_mesh.c, geometry/ob_model*.c) are compiled again for this
# target with coverage instrumentation (stb too: ob_model_open reads image
# headers and encodes raw embedded textures) (-fsanitize=fuzzer-no-link) and
# ASan + UBSan, whatever OB_SANITIZE says, so findings in our code are
# reported. libassimp itself is Debian's (not instrumented, asserts on).
if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "OB_FUZZ needs clang: configure with -DCMAKE_C_COMPILER=clang")
endif()

get_filename_component(OB_FUZZ_ROOT ${CMAKE_CURRENT_LIST_DIR}/.. ABSOLUTE)
set(OB_FUZZ_SANITIZE -g -fsanitize=address,undefined -fno-sanitize-recover=undefined
                     -fno-omit-frame-pointer)

file(GLOB OB_FUZZ_MODEL_SOURCES CONFIGURE_DEPENDS ${OB_FUZZ_ROOT}/geometry/ob_model*.c)
add_library(ob_fuzz_model_lib STATIC
            ${OB_FUZZ_ROOT}/engine/ob_core.c
            ${OB_FUZZ_ROOT}/engine/ob_stb_impl.c
            ${OB_FUZZ_ROOT}/geometry/ob_mesh.c
            ${OB_FUZZ_MODEL_SOURCES})
target_include_directories(ob_fuzz_model_lib PUBLIC ${OB_FUZZ_ROOT}/engine
                                                    ${OB_FUZZ_ROOT}/geometry ${STB_INCLUDE_DIR})
target_compile_options(ob_fuzz_model_lib PRIVATE ${OB_FUZZ_SANITIZE} -fsanitize=fuzzer-no-link)
target_link_libraries(ob_fuzz_model_lib PUBLIC PkgConfig::ASSIMP Threads::Threads m)

add_executable(fuzz_model ${CMAKE_CURRENT_LIST_DIR}/fuzz_model.c)
target_compile_options(fuzz_model PRIVATE ${OB_FUZZ_SANITIZE} -fsanitize=fuzzer)
target_link_options(fuzz_model PRIVATE ${OB_FUZZ_SANITIZE} -fsanitize=fuzzer)
target_link_libraries(fuzz_model PRIVATE ob_fuzz_model_lib)

# One minute of fuzzing from the seeds (label fuzz; not part of `ctest -L gpu`),
# in fork mode so that assimp's own crashes do not end it, then a triage of
# every saved input: the test fails only for a finding in our code (see
# fuzz/model_run.cmake). New inputs go to a corpus folder in the build tree;
# the seeds stay read-only.
add_test(NAME fuzz_model
         COMMAND ${CMAKE_COMMAND} -DFUZZER=$<TARGET_FILE:fuzz_model>
                 -DWORK=${CMAKE_BINARY_DIR}/fuzz/corpus-model
                 -DSEEDS=${CMAKE_CURRENT_LIST_DIR}/corpus/model
                 -DARTIFACTS=${CMAKE_BINARY_DIR}/fuzz/artifacts-model -DSECONDS=${OB_FUZZ_SECONDS}
                 -P ${CMAKE_CURRENT_LIST_DIR}/model_run.cmake)
set_tests_properties(fuzz_model PROPERTIES LABELS fuzz TIMEOUT 600)
