# A log replays exactly even after assets/ changed: record a short run, copy the data folder (assets/
# and maps/, what $LIDARLOOP_DATA points at), change the vehicle there (wheelbase and steering ratio,
# which the localizer's motion model uses), replay with that copy in effect: the estimates must still
# be the live run's, byte for byte, since the log carries the vehicle the run had.
# -DLIDARLOOP=... -DSCENARIO=... -DDATA=<the source tree> -DWORKDIR=...
file(REMOVE_RECURSE ${WORKDIR})
file(MAKE_DIRECTORY ${WORKDIR}/data)
execute_process(COMMAND ${LIDARLOOP} run ${SCENARIO} --duration 3 --record ${WORKDIR}/run.mcap --out ${WORKDIR}/live
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "run exited ${code}\n${out}\n${err}")
endif()

file(COPY ${DATA}/assets ${DATA}/maps DESTINATION ${WORKDIR}/data)
set(vehicle ${WORKDIR}/data/assets/vehicle.yaml)
file(READ ${vehicle} text)
string(REGEX REPLACE "\nlf: [0-9.]+" "\nlf: 1.5" edited "${text}")
string(REGEX REPLACE "\nsteering_ratio: [0-9.]+" "\nsteering_ratio: 14.0" edited "${edited}")
if(edited STREQUAL text OR NOT edited MATCHES "\nlf: 1.5" OR NOT edited MATCHES "\nsteering_ratio: 14.0")
  message(FATAL_ERROR "could not edit ${vehicle}")
endif()
file(WRITE ${vehicle} "${edited}")

execute_process(COMMAND ${CMAKE_COMMAND} -E env LIDARLOOP_DATA=${WORKDIR}/data ${LIDARLOOP} replay ${WORKDIR}/run.mcap
                        --out ${WORKDIR}/replay
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "replay exited ${code}\n${out}\n${err}")
endif()
if(err MATCHES "note:")
  message(FATAL_ERROR "replay of a complete log should need no note:\n${err}")
endif()
foreach(file estimate.tum truth.tum)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORKDIR}/live/${file} ${WORKDIR}/replay/${file}
                  RESULT_VARIABLE differ)
  if(differ)
    message(FATAL_ERROR "with a changed assets/vehicle.yaml, replay's ${file} differs from the live run's")
  endif()
endforeach()
message(STATUS "assets/vehicle.yaml changed (lf 1.5, steering_ratio 14): replay still gives the live run's estimates")
