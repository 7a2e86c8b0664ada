# Installing ofv's libraries as components of the `ofv` CMake package.
#
# Each library calls ofv_install_component(<comp> ...) next to its target:
# the library installs to lib/, its headers to include/, and its targets to
# lib/cmake/ofv/ofv_<comp>Targets.cmake as ofv::<comp>. ofvConfig.cmake
# (cmake/ofvConfig.cmake.in, written by ofv_write_package_config()) then loads
# only the requested components, the ofv components they link, and the
# third-party packages those need.

include(CMakePackageConfigHelpers)
set(OFV_CMAKE_INSTALL_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/ofv)

#[[
ofv_install_component(<comp> [INCLUDE_ROOT <dir> HEADER_DIRS <dir>...]
                      [DEPENDS <code>...] [PRIVATE_DEPENDS <code>...] [AFTER_LOAD <code>...])

  <comp>           component name; the target is ofv_<comp>, exported as ofv::<comp>.
  INCLUDE_ROOT     the folder the component's headers are included from
                   (relative to the current source folder; default include).
  HEADER_DIRS      its folders of headers to install, relative to INCLUDE_ROOT
                   (e.g. ofv/servo goes to include/ofv/servo).
  DEPENDS          CMake lines the package config runs before loading the
                   component: the third-party packages its public interface needs.
  PRIVATE_DEPENDS  lines needed as well when ofv is built as static libraries
                   (a shared library carries its private dependencies itself).
  AFTER_LOAD       lines run once ofv::<comp> exists.
#]]
function(ofv_install_component comp)
  cmake_parse_arguments(arg "" "INCLUDE_ROOT" "HEADER_DIRS;DEPENDS;PRIVATE_DEPENDS;AFTER_LOAD" ${ARGN})
  if(NOT arg_INCLUDE_ROOT)
    set(arg_INCLUDE_ROOT include)
  endif()
  set(target ofv_${comp})
  # Libraries find their siblings next to them, wherever the prefix is moved.
  # 0.x: the ABI may change with every minor version.
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${comp} INSTALL_RPATH "$ORIGIN"
    VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
  install(TARGETS ${target} EXPORT ofv_${comp}Targets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  foreach(dir ${arg_HEADER_DIRS})
    if(NOT IS_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/${arg_INCLUDE_ROOT}/${dir} AND NOT IS_DIRECTORY ${arg_INCLUDE_ROOT}/${dir})
      message(FATAL_ERROR "ofv_install_component(${comp}): no header folder ${arg_INCLUDE_ROOT}/${dir}")
    endif()
    get_filename_component(parent ${dir} DIRECTORY)
    install(DIRECTORY ${arg_INCLUDE_ROOT}/${dir} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/${parent}
      FILES_MATCHING PATTERN "*.h")
  endforeach()
  install(EXPORT ofv_${comp}Targets NAMESPACE ofv:: DESTINATION ${OFV_CMAKE_INSTALL_DIR})

  set(code ${arg_DEPENDS})
  if(NOT BUILD_SHARED_LIBS)
    list(APPEND code ${arg_PRIVATE_DEPENDS})
  endif()
  list(JOIN code "\n  " code)
  set_property(GLOBAL APPEND PROPERTY OFV_INSTALLED_COMPONENTS ${comp})
  set_property(GLOBAL PROPERTY OFV_COMPONENT_${comp}_CODE "${code}")
  list(JOIN arg_AFTER_LOAD "\n  " after)
  set_property(GLOBAL PROPERTY OFV_COMPONENT_${comp}_AFTER "${after}")
endfunction()

# The ofv components a component links (publicly or not: a shared library's
# private ofv dependencies must exist as targets too, for the linker's
# -rpath-link), read from the target itself so that it cannot go stale.
function(_ofv_component_links comp out)
  get_target_property(links ofv_${comp} LINK_LIBRARIES)
  get_property(all GLOBAL PROPERTY OFV_INSTALLED_COMPONENTS)
  set(deps)
  foreach(l IN LISTS links)
    foreach(c IN LISTS all)
      if(l STREQUAL "ofv_${c}" OR l STREQUAL "ofv::${c}")
        list(APPEND deps ${c})
      endif()
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES deps)
  set(${out} "${deps}" PARENT_SCOPE)
endfunction()

# Writes and installs ofvConfig.cmake and ofvConfigVersion.cmake. Call once,
# after every library's ofv_install_component().
function(ofv_write_package_config)
  get_property(components GLOBAL PROPERTY OFV_INSTALLED_COMPONENTS)
  set(OFV_COMPONENTS "${components}")
  set(OFV_COMPONENT_TABLE "")
  foreach(comp IN LISTS components)
    _ofv_component_links(${comp} deps)
    get_property(code GLOBAL PROPERTY OFV_COMPONENT_${comp}_CODE)
    get_property(after GLOBAL PROPERTY OFV_COMPONENT_${comp}_AFTER)
    string(APPEND OFV_COMPONENT_TABLE
      "set(_ofv_${comp}_links \"${deps}\")\n"
      "macro(_ofv_${comp}_find_dependencies)\n  ${code}\nendmacro()\n"
      "macro(_ofv_${comp}_after_load)\n  ${after}\nendmacro()\n")
  endforeach()
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/ofvConfig.cmake.in
    ${PROJECT_BINARY_DIR}/ofvConfig.cmake INSTALL_DESTINATION ${OFV_CMAKE_INSTALL_DIR}
    PATH_VARS CMAKE_INSTALL_DATADIR)
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/ofvConfigVersion.cmake
    COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/ofvConfig.cmake ${PROJECT_BINARY_DIR}/ofvConfigVersion.cmake
    DESTINATION ${OFV_CMAKE_INSTALL_DIR})
endfunction()
