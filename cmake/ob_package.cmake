# Obelisk as an installable package (included by the top CMakeLists.txt).
#
#   lib/libobelisk.a, lib/libobelisk.so.<major.minor> (+ links)
#   include/obelisk/*.h          the public headers, flat; obelisk.h includes them all
#   share/obelisk/shaders/       what the standard effects compile at run time
#   lib/pkgconfig/obelisk.pc     `pkg-config --cflags --libs obelisk` (shared library)
#   lib/cmake/Obelisk/           find_package(Obelisk): Obelisk::obelisk (shared),
#                                Obelisk::obelisk_static
#
# Both libraries are the same position-independent objects as the in-tree
# layer libraries (ob_layer), so nothing is compiled twice. Every installed
# path is relative to the prefix: `cmake --install build --prefix DIR` gives
# a working package in DIR, and the package can be moved as a whole.

# ------------------------------------------------------------ public headers
# The contract (DESIGN.md §1). Not installed: *_internal.h (each layer's own
# structs) and materials/ob_shader_source.h (the shader compiler's include
# expander). No installed header may include one of them: the package_headers
# test compiles every installed header alone against the install tree.
# views/scene/ob_json_read.h (the scene-file parser's cJSON reader) is internal
# too: cJSON stays a private dependency.
# The extension headers ob_renderer_layer.h and ob_views_layer.h are
# installed (custom views and materials need them, docs/extending.md) but
# obelisk.h includes neither: a program that only renders never sees the hooks.
# ob_reflect.h is public because ob_params.h, ob_program.h and ob_shader.h
# take and return its plain structs (custom effects use the reflection).
set(OB_PUBLIC_HEADERS
    engine/ob_core.h engine/ob_device.h engine/ob_math.h engine/ob_params.h
    engine/ob_pipeline_manager.h engine/ob_program.h engine/ob_reflect.h
    engine/ob_renderer.h engine/ob_renderer_layer.h engine/ob_resources.h engine/ob_scene.h
    engine/ob_texture.h engine/ob_view.h
    materials/ob_effect.h materials/ob_material.h materials/ob_shader.h
    geometry/ob_geometry.h geometry/ob_mesh.h geometry/ob_model.h
    views/ob_views.h views/ob_views_layer.h
    views/scene/ob_stack.h views/scene/ob_stack_content.h views/scene/ob_framing.h
    views/scene/ob_scene_file.h views/scene/ob_scene_load.h
    views/scene/ob_model_instance.h views/scene/obelisk.h)

# ------------------------------------------------------------------ shaders
# The shaders are looked up relative to the binary that holds the engine
# (materials/ob_shader_dir.c): <dir of libobelisk.so or of the executable>/
# OB_SHADER_REL_DIR. The build tree gets the same layout — build/share/
# obelisk/shaders links to the source folder, so build/bin/* and build/tests/*
# find them at ../share/obelisk/shaders, and an edited shader is used at once.
set(OB_SHADER_INSTALL_DIR ${CMAKE_INSTALL_DATADIR}/obelisk/shaders)
file(RELATIVE_PATH OB_SHADER_REL_DIR ${CMAKE_INSTALL_FULL_LIBDIR}
     ${CMAKE_INSTALL_FULL_DATADIR}/obelisk/shaders)
set_source_files_properties(materials/ob_shader_dir.c PROPERTIES COMPILE_DEFINITIONS
    "OB_SHADER_REL_DIR=\"${OB_SHADER_REL_DIR}\";OB_SHADER_INSTALL_DIR=\"${CMAKE_INSTALL_FULL_DATADIR}/obelisk/shaders\"")
file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/share/obelisk)
file(CREATE_LINK ${CMAKE_SOURCE_DIR}/materials/shaders ${CMAKE_BINARY_DIR}/share/obelisk/shaders
     SYMBOLIC COPY_ON_ERROR)

# ---------------------------------------------------------------- libraries
get_property(OB_LAYER_OBJECTS GLOBAL PROPERTY OB_LAYER_OBJECTS)
set(OB_LIBRARY_OBJECTS "")
foreach(layer ${OB_LAYER_OBJECTS})
  list(APPEND OB_LIBRARY_OBJECTS $<TARGET_OBJECTS:${layer}>)
endforeach()

# What the engine's code links besides Vulkan (the headers' only third-party
# include) and libc: private to the shared library, link-only for the static one.
set(OB_LIBRARY_PRIVATE_LINK PkgConfig::GLSLANG glslang-default-resource-limits stdc++
    ${SPIRV_CROSS_C} PkgConfig::ASSIMP PkgConfig::CJSON PkgConfig::ZLIB Threads::Threads m ${CMAKE_DL_LIBS})

add_library(obelisk SHARED ${OB_LIBRARY_OBJECTS})
add_library(obelisk_static STATIC ${OB_LIBRARY_OBJECTS})
set_target_properties(obelisk PROPERTIES
    VERSION ${PROJECT_VERSION}
    # 0.x: a minor version may break the ABI, so it is part of the SONAME.
    SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR}
    LIBRARY_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/lib)
set_target_properties(obelisk_static PROPERTIES OUTPUT_NAME obelisk
    ARCHIVE_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/lib)
if(NOT OB_SANITIZE)
  # Every symbol the library needs is linked in (sanitizer runtimes come with
  # the executable, so their builds cannot ask for this).
  target_link_options(obelisk PRIVATE -Wl,--no-undefined)
endif()
# Only ob_* is exported (cmake/obelisk.map says why).
target_link_options(obelisk PRIVATE -Wl,--version-script=${CMAKE_SOURCE_DIR}/cmake/obelisk.map)
set_property(TARGET obelisk APPEND PROPERTY LINK_DEPENDS ${CMAKE_SOURCE_DIR}/cmake/obelisk.map)
target_link_libraries(obelisk PUBLIC Vulkan::Vulkan PRIVATE ${OB_LIBRARY_PRIVATE_LINK})
# The installed static library's link interface comes from the package's
# own look-ups (cmake/ObeliskConfig.cmake.in); in the build tree nothing links it.
# LINK_ONLY: a program linking it gets the private dependencies' libraries,
# never their include folders (the public headers need Vulkan's only).
target_link_libraries(obelisk_static INTERFACE Vulkan::Vulkan
    $<INSTALL_INTERFACE:$<LINK_ONLY:PkgConfig::Obelisk_PRIVATE>>
    $<INSTALL_INTERFACE:glslang-default-resource-limits stdc++ Threads::Threads m ${CMAKE_DL_LIBS}>)
foreach(lib obelisk obelisk_static)
  target_include_directories(${lib} INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  target_compile_definitions(${lib} INTERFACE CGLM_FORCE_DEPTH_ZERO_TO_ONE)
endforeach()
set_target_properties(obelisk_static PROPERTIES EXPORT_NAME obelisk_static)

# ------------------------------------------------------------------ install
install(TARGETS obelisk EXPORT ObeliskTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS obelisk_static EXPORT ObeliskStaticTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(FILES ${OB_PUBLIC_HEADERS} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/obelisk)
install(DIRECTORY materials/shaders/ DESTINATION ${OB_SHADER_INSTALL_DIR})

set(OB_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/Obelisk)
install(EXPORT ObeliskTargets NAMESPACE Obelisk:: DESTINATION ${OB_CMAKE_DIR})
install(EXPORT ObeliskStaticTargets NAMESPACE Obelisk:: DESTINATION ${OB_CMAKE_DIR})
include(CMakePackageConfigHelpers)
configure_package_config_file(cmake/ObeliskConfig.cmake.in
    ${CMAKE_BINARY_DIR}/package/ObeliskConfig.cmake
    INSTALL_DESTINATION ${OB_CMAKE_DIR} PATH_VARS OB_SHADER_INSTALL_DIR)
# 0.x: only the same minor version is compatible.
write_basic_package_version_file(${CMAKE_BINARY_DIR}/package/ObeliskConfigVersion.cmake
    COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/package/ObeliskConfig.cmake
              ${CMAKE_BINARY_DIR}/package/ObeliskConfigVersion.cmake
        DESTINATION ${OB_CMAKE_DIR})

# obelisk.pc: the prefix is found from the file's own place (${pcfiledir}).
# Its Libs.private is what linking libobelisk.a needs: the private
# dependencies' static link flags as their pkg-config files gave them at
# configure time, -L for folders the linker does not search anyway, each
# library kept at its last place (static link order).
set(OB_PC_PRIVATE_FLAGS -lglslang-default-resource-limits ${GLSLANG_STATIC_LDFLAGS})
get_filename_component(OB_SPIRV_CROSS_DIR ${SPIRV_CROSS_C} DIRECTORY)
list(APPEND OB_PC_PRIVATE_FLAGS -L${OB_SPIRV_CROSS_DIR} -lspirv-cross-c-shared ${ASSIMP_STATIC_LDFLAGS}
     ${CJSON_STATIC_LDFLAGS} ${ZLIB_STATIC_LDFLAGS} -lstdc++ -lpthread -lm)
foreach(lib ${CMAKE_DL_LIBS})
  list(APPEND OB_PC_PRIVATE_FLAGS -l${lib})
endforeach()
set(OB_PC_LIBS_PRIVATE "")
list(REVERSE OB_PC_PRIVATE_FLAGS)
foreach(flag ${OB_PC_PRIVATE_FLAGS})
  if(flag MATCHES "^-L(.*)$" AND CMAKE_MATCH_1 IN_LIST CMAKE_C_IMPLICIT_LINK_DIRECTORIES)
    continue()
  endif()
  if(NOT flag IN_LIST OB_PC_LIBS_PRIVATE)
    list(APPEND OB_PC_LIBS_PRIVATE ${flag})
  endif()
endforeach()
list(REVERSE OB_PC_LIBS_PRIVATE)
string(JOIN " " OB_PC_LIBS_PRIVATE ${OB_PC_LIBS_PRIVATE})
file(RELATIVE_PATH OB_PC_PREFIX ${CMAKE_INSTALL_FULL_LIBDIR}/pkgconfig ${CMAKE_INSTALL_PREFIX})
string(REGEX REPLACE "/$" "" OB_PC_PREFIX "${OB_PC_PREFIX}")
configure_file(cmake/obelisk.pc.in ${CMAKE_BINARY_DIR}/package/obelisk.pc @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/package/obelisk.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
