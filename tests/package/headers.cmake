# Every installed header compiles alone against the install tree only (no
# source folder on the include path): proves no public header includes an
# internal one or depends on being included after another. obelisk.h, the
# umbrella, is one of them.
# Run by ctest: cmake -DCC=<compiler> -DPREFIX=<dir> -DOUT=<dir> -P headers.cmake
foreach(var CC PREFIX OUT)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "package headers: -D${var}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})
file(GLOB headers RELATIVE ${PREFIX}/include/obelisk ${PREFIX}/include/obelisk/*.h)
list(LENGTH headers count)
if(count LESS 10)
  message(FATAL_ERROR "only ${count} headers in ${PREFIX}/include/obelisk")
endif()
foreach(h ${headers})
  set(tu ${OUT}/${h}.c)
  file(WRITE ${tu} "#include <obelisk/${h}>\n#include <obelisk/${h}> /* guarded twice */\n")
  execute_process(COMMAND ${CC} -std=c11 -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes
                          -fsyntax-only -I${PREFIX}/include ${tu}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "<obelisk/${h}> does not compile alone against ${PREFIX}/include\n${out}${err}")
  endif()
endforeach()
message(STATUS "${count} installed headers compile alone")
