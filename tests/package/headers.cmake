# Every installed header compiles alone against the install tree only (no
# source folder on the include path): proves no public header includes an
# internal one or depends on being included after another. obelisk.h, the
# umbrella, is one of them. And obelisk.h does not reach the extension
# headers (ob_renderer_layer.h, ob_views_layer.h), which are installed.
# With -DSRC=<source>, docs/getting-started.md's header list names every
# installed header (a reader finds ob_model.h there, not by searching).
# Run by ctest: cmake -DCC=<compiler> -DPREFIX=<dir> -DOUT=<dir> [-DSRC=<source>] -P headers.cmake
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

# The extension headers (hooks for custom views and materials) are installed
# but reachable only when included by name: the user-facing headers keep
# them out.
set(tu ${OUT}/umbrella_without_layers.c)
file(WRITE ${tu} "#include <obelisk/obelisk.h>\n"
    "#if defined(OB_RENDERER_LAYER_H) || defined(OB_VIEWS_LAYER_H)\n"
    "#error obelisk.h reaches an extension header\n#endif\n"
    "int ob_renderer_queue_view; /* a conflicting declaration if it were declared */\n")
execute_process(COMMAND ${CC} -std=c11 -Wall -Wextra -Werror -fsyntax-only -I${PREFIX}/include ${tu}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "obelisk/obelisk.h brings in the extension API\n${out}${err}")
endif()
foreach(h ob_renderer_layer.h ob_views_layer.h)
  if(NOT EXISTS ${PREFIX}/include/obelisk/${h})
    message(FATAL_ERROR "extension header <obelisk/${h}> not installed")
  endif()
endforeach()
message(STATUS "obelisk.h keeps the extension headers out; both are installed")

if(DEFINED SRC)
  file(READ ${SRC}/docs/getting-started.md guide)
  set(unlisted "")
  foreach(h ${headers})
    string(FIND "${guide}" "${h}" at)
    if(at EQUAL -1)
      list(APPEND unlisted ${h})
    endif()
  endforeach()
  if(unlisted)
    message(FATAL_ERROR "docs/getting-started.md does not name these installed headers: ${unlisted}")
  endif()
  message(STATUS "docs/getting-started.md names all ${count} installed headers")
endif()
