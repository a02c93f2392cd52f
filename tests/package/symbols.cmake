# Every symbol libobelisk.so exports (nm -D --defined-only) is declared in an
# installed header: what a program can bind to is the documented contract
# and nothing else (DESIGN.md §1). Internal functions shared between files
# stay hidden (#pragma GCC visibility in *_internal.h, ob_json_read.h,
# ob_shader_source.h); cmake/obelisk.map keeps the rest (glslang, stb, ...)
# out. The headers are preprocessed, so a name mentioned in a comment does
# not count as declared.
# Run by ctest: cmake -DCC=<compiler> -DPREFIX=<dir> -DOUT=<dir> -P symbols.cmake
cmake_minimum_required(VERSION 3.20)   # IN_LIST
foreach(var CC PREFIX OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "package symbols: -D${var}=... is required")
  endif()
endforeach()
find_program(NM nm REQUIRED)
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
file(READ ${PREFIX}/libdir.txt libdir)
execute_process(COMMAND ${NM} -D --defined-only ${PREFIX}/${libdir}/libobelisk.so
                RESULT_VARIABLE code OUTPUT_VARIABLE symbols ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "nm -D libobelisk.so failed\n${err}")
endif()

# Every installed header, preprocessed together.
file(GLOB headers RELATIVE ${PREFIX}/include/obelisk ${PREFIX}/include/obelisk/*.h)
set(tu "")
foreach(h ${headers})
  string(APPEND tu "#include <obelisk/${h}>\n")
endforeach()
file(WRITE ${OUT}/all_headers.c "${tu}")
execute_process(COMMAND ${CC} -std=c11 -E -I${PREFIX}/include ${OUT}/all_headers.c
                RESULT_VARIABLE code OUTPUT_VARIABLE declared ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "preprocessing the installed headers failed\n${err}")
endif()
string(REGEX MATCHALL "ob_[A-Za-z0-9_]*" names "${declared}")
list(REMOVE_DUPLICATES names)

string(REPLACE "\n" ";" lines "${symbols}")
set(exported 0)
set(undeclared "")
foreach(line ${lines})
  # "<address> <type> <name>[@@version]"; the version node itself is type A.
  if(NOT line MATCHES "^[0-9a-fA-F]+ ([A-Za-z]) ([^@ ]+)")
    continue()
  endif()
  set(type ${CMAKE_MATCH_1})
  set(name ${CMAKE_MATCH_2})
  if(type STREQUAL "A")
    continue()
  endif()
  math(EXPR exported "${exported} + 1")
  if(NOT name IN_LIST names)
    list(APPEND undeclared "${name} (${type})")
  endif()
endforeach()
if(exported LESS 100)
  message(FATAL_ERROR "only ${exported} symbols exported by libobelisk.so:\n${symbols}")
endif()
if(undeclared)
  list(JOIN undeclared "\n  " undeclared)
  message(FATAL_ERROR "libobelisk.so exports symbols no installed header declares (hide them: "
                      "#pragma GCC visibility in the layer's *_internal.h):\n  ${undeclared}")
endif()
message(STATUS "${exported} exported symbols, each declared in an installed header")
