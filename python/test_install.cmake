# ctest python.install: installs the build into a scratch prefix, moves the
# prefix, and imports the module from it with a clean PYTHONPATH: the
# package's folder, its RPATH to libofv_*.so and the built-in scenarios
# found relative to the libraries.
#   cmake -DOFV_BINARY_DIR=... -DWORK_DIR=... -DPYTHON=... -P test_install.cmake
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${OFV_BINARY_DIR} --prefix ${WORK_DIR}/prefix
                OUTPUT_QUIET RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed (${rc})")
endif()
file(RENAME ${WORK_DIR}/prefix ${WORK_DIR}/moved)
set(site ${WORK_DIR}/moved/lib/python3/dist-packages)
if(NOT EXISTS ${site}/ofv/__init__.py)
  message(FATAL_ERROR "no ${site}/ofv/__init__.py after cmake --install")
endif()
set(check [=[
import os, sys
import numpy as np
import ofv
site = os.path.realpath(sys.argv[1])
assert os.path.realpath(ofv.__file__).startswith(site), ofv.__file__
e = ofv.estimate_view(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.05, 0.2]]), r_sphere=0.4)
assert e.is_free, e
if ofv.HAS_SIMULATION:
    s = ofv.load_scenario("dvd-static")
    assert os.path.realpath(s.path).startswith(os.path.realpath(sys.argv[2])), s.path
    ep = ofv.simulate(s, duration=0.2, perception="ground-truth")
    assert ep.metrics["steps"] == len(ep.trajectory["time"]) > 0
print("imported", ofv.__file__, ofv.__version__)
]=])
execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${site} --unset=OFV_DATA_DIR --unset=OFV_SCENARIO_DIR
                        ${PYTHON} -c "${check}" ${site} ${WORK_DIR}/moved/share/ofv
                WORKING_DIRECTORY ${WORK_DIR} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the installed module did not import or run (${rc})")
endif()
