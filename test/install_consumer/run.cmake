cmake_minimum_required(VERSION 3.16)
# The install test (ctest label `install`): installs the built ofv into a
# scratch prefix, moves the prefix (an install must not depend on where it was
# made), then, against the moved prefix only:
#  - the installed `ofv` lists the built-in scenarios and runs one;
#  - OFV_DATA_DIR points it at another data folder;
#  - test/install_consumer* configure with find_package(ofv COMPONENTS ...),
#    build and run: core (the estimator), servo (the sphere feature in the
#    user's vpServo loop), loop (a short simulated episode), display (the
#    live display refuses without a display);
#  - asking for a component ofv does not have fails, naming it.
# Arguments: OFV_BINARY_DIR, TEST_SOURCE_DIR (test/), WORK_DIR, COMPONENTS
# (the components built), SCENARIOS (the built-in scenario names), both
# comma-separated.
string(REPLACE "," ";" COMPONENTS "${COMPONENTS}")
string(REPLACE "," ";" SCENARIOS "${SCENARIOS}")
file(REMOVE_RECURSE ${WORK_DIR})
unset(ENV{OFV_DATA_DIR})
unset(ENV{OFV_SCENARIO_DIR})

function(run)
  execute_process(COMMAND ${ARGV} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGV}\n${out}")
  endif()
  message(STATUS "${out}")
  set(out "${out}" PARENT_SCOPE)
endfunction()

function(consumer name)
  run(${CMAKE_COMMAND} -S ${TEST_SOURCE_DIR}/${name} -B ${WORK_DIR}/${name}
      -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
  run(${CMAKE_COMMAND} --build ${WORK_DIR}/${name})
  file(GLOB exe ${WORK_DIR}/${name}/consumer*)
  run(${exe})
endfunction()

run(${CMAKE_COMMAND} --install ${OFV_BINARY_DIR} --prefix ${WORK_DIR}/installed)
set(prefix ${WORK_DIR}/moved)
file(RENAME ${WORK_DIR}/installed ${prefix})

# Every public header of an installed component is installed.
set(src ${TEST_SOURCE_DIR}/..)
file(GLOB_RECURSE headers RELATIVE ${src} ${src}/include/ofv/*.h ${src}/servo/include/ofv/*.h
                                          ${src}/sim/include/ofv/*.h ${src}/sim/loop/include/ofv/*.h
                                          ${src}/display/include/ofv/*.h)
foreach(h IN LISTS headers)
  string(REGEX REPLACE "^.*include/(ofv/.*)$" "\\1" installed ${h})
  string(REGEX MATCH "^ofv/([a-z]+)/" dir ${installed})
  set(comp ${CMAKE_MATCH_1})
  if(NOT comp)
    set(comp core)
  elseif(comp STREQUAL "sources")
    set(comp perception)
  endif()
  if(comp IN_LIST COMPONENTS AND NOT EXISTS ${prefix}/include/${installed})
    message(FATAL_ERROR "${h} (component ${comp}) is not installed as include/${installed}")
  endif()
endforeach()

if(loop IN_LIST COMPONENTS)
  run(${prefix}/bin/ofv simulate --help)
  string(REGEX MATCH "Built-in scenarios: [^\n]*" listed "${out}")
  foreach(name IN LISTS SCENARIOS)
    if(NOT listed MATCHES "[ ,]${name}(,|$)")
      message(FATAL_ERROR "ofv simulate --help does not list the built-in scenario ${name}:\n${out}")
    endif()
  endforeach()
  run(${prefix}/bin/ofv simulate dvd-static --set duration=0.3 --no-pictures --perception ground-truth
      --out ${WORK_DIR}/simulate)
  if(NOT EXISTS ${WORK_DIR}/simulate/metrics.json)
    message(FATAL_ERROR "ofv simulate wrote no metrics.json")
  endif()
  file(COPY ${prefix}/share/ofv/scenarios/dvd-static.yaml DESTINATION ${WORK_DIR}/data/scenarios)
  file(RENAME ${WORK_DIR}/data/scenarios/dvd-static.yaml ${WORK_DIR}/data/scenarios/only-here.yaml)
  run(${CMAKE_COMMAND} -E env OFV_DATA_DIR=${WORK_DIR}/data ${prefix}/bin/ofv simulate --help)
  string(REGEX MATCH "Built-in scenarios: [^\n]*" listed "${out}")
  if(NOT listed STREQUAL "Built-in scenarios: only-here")
    message(FATAL_ERROR "with OFV_DATA_DIR set, ofv simulate --help should list only only-here:\n${out}")
  endif()
endif()

consumer(install_consumer)
if(servo IN_LIST COMPONENTS)
  consumer(install_consumer_servo)
endif()
if(loop IN_LIST COMPONENTS)
  consumer(install_consumer_loop)
endif()
if(display IN_LIST COMPONENTS)
  consumer(install_consumer_display)
endif()

execute_process(COMMAND ${CMAKE_COMMAND} -S ${TEST_SOURCE_DIR}/install_consumer_missing
                        -B ${WORK_DIR}/install_consumer_missing -DCMAKE_PREFIX_PATH=${prefix}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(rc EQUAL 0 OR NOT out MATCHES "not installed: nosuch")
  message(FATAL_ERROR "find_package(ofv COMPONENTS nosuch) should fail naming nosuch (${rc}):\n${out}")
endif()
message(STATUS "find_package(ofv COMPONENTS core nosuch) fails as it should:\n${out}")
