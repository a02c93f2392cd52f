# fuzz/model.cmake — the libFuzzer target for the model loader (fuzz_model)
# and its bounded ctest run, included from fuzz/CMakeLists.txt (which the
# top level adds when OB_FUZZ is ON). Needs clang. The loader and what it uses (engine/ob_core.c,
# geometry/ob_mesh.c, geometry/ob_mesh_simplify.c, geometry/ob_model*.c) are compiled again for this
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
            ${OB_FUZZ_ROOT}/geometry/ob_mesh_simplify.c
            ${OB_FUZZ_MODEL_SOURCES})
target_include_directories(ob_fuzz_model_lib PUBLIC ${OB_FUZZ_ROOT}/engine
                                                    ${OB_FUZZ_ROOT}/geometry ${STB_INCLUDE_DIR})
target_compile_options(ob_fuzz_model_lib PRIVATE ${OB_FUZZ_SANITIZE} -fsanitize=fuzzer-no-link)
target_link_libraries(ob_fuzz_model_lib PUBLIC PkgConfig::ASSIMP PkgConfig::ZLIB Threads::Threads m)

add_executable(fuzz_model ${CMAKE_CURRENT_LIST_DIR}/fuzz_model.c)
target_compile_options(fuzz_model PRIVATE ${OB_FUZZ_SANITIZE} -fsanitize=fuzzer)
target_link_options(fuzz_model PRIVATE ${OB_FUZZ_SANITIZE} -fsanitize=fuzzer)
target_link_libraries(fuzz_model PRIVATE ob_fuzz_model_lib)

# CI (label fuzz; not part of `ctest -L gpu`) replays, deterministically,
# every saved input: the seeds, the findings fixed so far
# (corpus/model-findings) and the inputs known to crash inside assimp
# (corpus/model-assimp-known); each is run alone and triaged by
# fuzz/model_run.cmake, and the test fails only for a report in our code.
# Exploratory fuzzing is not a test: `./setup.sh fuzz-explore` (MODE=explore).
add_test(NAME fuzz_model
         COMMAND ${CMAKE_COMMAND} -DMODE=replay -DFUZZER=$<TARGET_FILE:fuzz_model>
                 "-DSEEDS=${CMAKE_CURRENT_LIST_DIR}/corpus/model;${CMAKE_CURRENT_LIST_DIR}/corpus/model-findings;${CMAKE_CURRENT_LIST_DIR}/corpus/model-assimp-known"
                 -P ${CMAKE_CURRENT_LIST_DIR}/model_run.cmake)
set_tests_properties(fuzz_model PROPERTIES LABELS fuzz TIMEOUT 900)
