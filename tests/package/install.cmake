# Installs the build into a fresh prefix and checks what is there: both
# libraries (the shared one with its SONAME link), the public headers and no
# internal one, the shaders, obelisk.pc and the CMake package. The fixture
# the other package_* tests use.
# Run by ctest: cmake -DBUILD=<build> -DPREFIX=<dir> -P install.cmake
foreach(var BUILD PREFIX)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "package install: -D${var}=... is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${PREFIX})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD} --prefix ${PREFIX}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${code})\n${out}\n${err}")
endif()

# lib/ or lib/<multiarch>/, as GNUInstallDirs chose.
file(GLOB_RECURSE config RELATIVE ${PREFIX} ${PREFIX}/*/ObeliskConfig.cmake)
if(NOT config MATCHES "^(.*)/cmake/Obelisk/ObeliskConfig.cmake$")
  message(FATAL_ERROR "no <libdir>/cmake/Obelisk/ObeliskConfig.cmake under ${PREFIX}: ${config}")
endif()
set(libdir ${CMAKE_MATCH_1})
foreach(f ${libdir}/libobelisk.a ${libdir}/libobelisk.so ${libdir}/pkgconfig/obelisk.pc
          ${libdir}/cmake/Obelisk/ObeliskConfigVersion.cmake
          ${libdir}/cmake/Obelisk/ObeliskTargets.cmake
          ${libdir}/cmake/Obelisk/ObeliskStaticTargets.cmake
          include/obelisk/obelisk.h include/obelisk/ob_renderer.h include/obelisk/ob_stack.h
          share/obelisk/shaders/pbr.frag share/obelisk/shaders/common.glsl)
  if(NOT EXISTS ${PREFIX}/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
file(GLOB sonames ${PREFIX}/${libdir}/libobelisk.so.*)
if(NOT sonames)
  message(FATAL_ERROR "libobelisk.so has no versioned file (SONAME)")
endif()
file(GLOB internal ${PREFIX}/include/obelisk/*_internal.h ${PREFIX}/include/obelisk/ob_shader_source.h)
if(internal)
  message(FATAL_ERROR "internal headers installed: ${internal}")
endif()
# The shaders are found relative to the library, never through the tree it
# was built from: no installed text file may name the source folder.
if(DEFINED SRC)
  file(GLOB_RECURSE texts ${PREFIX}/include/* ${PREFIX}/share/* ${PREFIX}/${libdir}/cmake/*
       ${PREFIX}/${libdir}/pkgconfig/*)
  foreach(t ${texts})
    file(READ ${t} body)
    string(FIND "${body}" "${SRC}" at)
    if(NOT at EQUAL -1)
      message(FATAL_ERROR "${t} names the source tree ${SRC}")
    endif()
  endforeach()
endif()
file(WRITE ${PREFIX}/libdir.txt ${libdir})
message(STATUS "installed into ${PREFIX} (libdir ${libdir})")
