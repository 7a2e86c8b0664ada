# Finds what the Python module needs and sets the option OFV_BUILD_PYTHON
# (default ON when everything is found; ON without it is an error).
#
# Debian's interpreter is the one python3-numpy, python3-pytest and
# python3-matplotlib (scripts/install-deps.sh) are installed for: it is
# preferred to a python3 earlier on PATH (pyenv, conda), which lacks them.
# -DPython3_EXECUTABLE=... chooses another.
if(NOT Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
  set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "Python 3 interpreter of the ofv module and its tests")
endif()
find_package(Python3 3.7 COMPONENTS Interpreter Development.Module QUIET)
set(PYBIND11_FINDPYTHON ON)  # pybind11 takes the Python3 found above
find_package(pybind11 2.6 CONFIG QUIET)
set(_ofv_python_missing "")
if(NOT Python3_FOUND)
  set(_ofv_python_missing "Python 3 headers (python3-dev)")
elseif(NOT pybind11_FOUND)
  set(_ofv_python_missing "pybind11 (pybind11-dev)")
else()
  execute_process(COMMAND ${Python3_EXECUTABLE} -c "import numpy"
                  RESULT_VARIABLE _ofv_numpy_rc OUTPUT_QUIET ERROR_QUIET)
  if(NOT _ofv_numpy_rc EQUAL 0)
    set(_ofv_python_missing "numpy for ${Python3_EXECUTABLE} (python3-numpy)")
  endif()
endif()
if(_ofv_python_missing)
  option(OFV_BUILD_PYTHON "Build the Python module ofv (pybind11)" OFF)
else()
  option(OFV_BUILD_PYTHON "Build the Python module ofv (pybind11)" ON)
endif()
if(OFV_BUILD_PYTHON AND _ofv_python_missing)
  message(FATAL_ERROR "OFV_BUILD_PYTHON is ON but ${_ofv_python_missing} was not found "
                      "(scripts/install-deps.sh installs it; or -DOFV_BUILD_PYTHON=OFF)")
elseif(OFV_BUILD_PYTHON)
  message(STATUS "Python module ofv: ${Python3_EXECUTABLE} ${Python3_VERSION}, pybind11 ${pybind11_VERSION}")
elseif(_ofv_python_missing)
  message(STATUS "Python module ofv: off, ${_ofv_python_missing} not found")
else()
  message(STATUS "Python module ofv: off (OFV_BUILD_PYTHON=OFF)")
endif()
