# `cpack -G DEB` in the build folder: a Debian package of everything
# `cmake --install` installs (the ofv program, the libraries, their headers,
# the CMake package and share/ofv), under /usr.
#
# It ships headers and the CMake package, so it depends on the -dev packages
# that ofvConfig.cmake (and a static build's link) finds; they pull in the
# run-time libraries the shared libraries link.
get_property(_ofv_components GLOBAL PROPERTY OFV_INSTALLED_COMPONENTS)
set(_ofv_deb_depends libeigen3-dev)
if(io IN_LIST _ofv_components OR loop IN_LIST _ofv_components)
  list(APPEND _ofv_deb_depends nlohmann-json3-dev)
endif()
if(perception IN_LIST _ofv_components)
  list(APPEND _ofv_deb_depends libpcl-dev libopencv-dev libopenni2-dev libtbb-dev)
endif()
if(sim IN_LIST _ofv_components)
  # `ofv render` writes PNG and video with OpenCV.
  list(APPEND _ofv_deb_depends libembree-dev libtbb-dev libyaml-cpp-dev libassimp-dev libopencv-dev)
endif()
if(servo IN_LIST _ofv_components)
  list(APPEND _ofv_deb_depends libvisp-dev)
endif()
if(loop IN_LIST _ofv_components)
  list(APPEND _ofv_deb_depends libyaml-cpp-dev)
endif()
list(APPEND _ofv_deb_depends gnuplot-nox)  # `ofv compare` plots
if(TARGET ofv_python)
  # The module ofv in /usr/lib/python3/dist-packages: built for one CPython
  # minor version (its extension's ABI), numpy at run time.
  math(EXPR _ofv_py_next "${Python3_VERSION_MINOR} + 1")
  list(APPEND _ofv_deb_depends "python3 (>= 3.${Python3_VERSION_MINOR})" "python3 (<< 3.${_ofv_py_next})" python3-numpy)
endif()
list(REMOVE_DUPLICATES _ofv_deb_depends)
list(JOIN _ofv_deb_depends ", " CPACK_DEBIAN_PACKAGE_DEPENDS)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME ofv)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_DESCRIPTION
    "ofv estimates occlusion-free views of an object from RGB-D frames and\n"
    "servoes a camera to them with ViSP. The package holds the ofv program,\n"
    "the libraries (core, io, perception, sim, servo, loop, display) with their\n"
    "headers and CMake package (find_package(ofv COMPONENTS ...)), the\n"
    "built-in scenarios and examples in /usr/share/ofv, and (when built) the\n"
    "Python module ofv (import ofv).")
list(JOIN CPACK_PACKAGE_DESCRIPTION "" CPACK_PACKAGE_DESCRIPTION)
set(CPACK_PACKAGE_CONTACT "ofv maintainers <ofv@localhost>")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # ofv_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# A shlibs file and the ldconfig trigger for the versioned libofv_*.so.
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
set(CPACK_STRIP_FILES ON)
include(CPack)
