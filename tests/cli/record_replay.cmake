# Record a run at one thread and at two: the logs must be byte-identical. Replay the log: the estimates,
# their statuses (replay compares each with the log's /localizer/status) and ground truth must be the
# live run's exactly, and so must every accuracy figure of metrics.json
# (latency is wall time and is not compared), the curb occlusion included (replay reads it from the log).
# With -DDATA=<source tree>: replay it once more with a copy of the data folder ($LIDARLOOP_DATA) whose
# assets/vehicle.yaml changed (wheelbase and steering ratio, which the localizer's motion model uses):
# the log carries the run's vehicle, so the estimates must still be the live run's.
# -DLIDARLOOP=... -DSCENARIO=... -DWORKDIR=... [-DMETHOD=...: the run's method, recorded in the log] [-DDATA=...]
# [-DLATENCY=MS: a fixed latency in closed loop; an exec: program's measured one is not repeatable]
# [-DPACKETS_ONLY=ON: record the scans only as the HDL-32E's packets, which replay decodes as a driver
#  does (the live localizer had the same clouds), and export them to PCD files the same way]
file(REMOVE_RECURSE ${WORKDIR})
file(MAKE_DIRECTORY ${WORKDIR})
set(method)
if(METHOD)
  set(method --method ${METHOD})
endif()
if(LATENCY)
  list(APPEND method --latency ${LATENCY})
endif()
set(record)
if(PACKETS_ONLY)
  set(record --packets-only)
endif()
foreach(threads 1 2)
  execute_process(COMMAND ${LIDARLOOP} run ${SCENARIO} --duration 6 --threads ${threads} ${method}
                          --record ${WORKDIR}/run_${threads}.mcap ${record} --out ${WORKDIR}/live_${threads}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "run at ${threads} thread(s) exited ${code}\n${out}\n${err}")
  endif()
endforeach()
execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORKDIR}/run_1.mcap ${WORKDIR}/run_2.mcap
                RESULT_VARIABLE differ)
if(differ)
  message(FATAL_ERROR "the logs recorded at 1 and 2 threads differ")
endif()
# replay_as_live(DIR WHAT ENV...): replays run_1.mcap into DIR (with the environment ENV) and checks
# that its estimates and truth are the live run's, byte for byte, and that it needed no note.
function(replay_as_live dir what)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env ${ARGN} ${LIDARLOOP} replay ${WORKDIR}/run_1.mcap --out ${dir}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0 OR err MATCHES "note:")
    message(FATAL_ERROR "${what}: replay exited ${code}\n${out}\n${err}")
  endif()
  # Replay compares every scan's /localizer/status (health, lost, protection bounds) with the log's.
  if(NOT out MATCHES "status     the localizer's status matched the log's at all [0-9]+ scans")
    message(FATAL_ERROR "${what}: replay did not find the log's localizer statuses matched\n${out}")
  endif()
  foreach(file estimate.tum truth.tum)
    execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORKDIR}/live_1/${file} ${dir}/${file}
                    RESULT_VARIABLE differ)
    if(differ)
      message(FATAL_ERROR "${what}: replay's ${file} differs from the live run's")
    endif()
  endforeach()
endfunction()
replay_as_live(${WORKDIR}/replay "replay")
file(READ ${WORKDIR}/live_1/metrics.json live)
file(READ ${WORKDIR}/replay/metrics.json replay)
foreach(key frames lateral_rmse_m longitudinal_rmse_m heading_rmse_deg max_position_error_m curb_hidden_fraction
            curb_hidden_fraction_max pass)
  string(JSON a GET "${live}" ${key})
  string(JSON b GET "${replay}" ${key})
  if(NOT a STREQUAL b)
    message(FATAL_ERROR "metrics.json ${key}: live ${a}, replay ${b}")
  endif()
endforeach()
message(STATUS "1 and 2 threads: identical logs; replay: identical estimates, truth and metrics")
if(PACKETS_ONLY)
  execute_process(COMMAND ${LIDARLOOP} info ${WORKDIR}/run_1.mcap RESULT_VARIABLE code OUTPUT_VARIABLE out)
  if(NOT code EQUAL 0 OR out MATCHES "/lidar/points" OR NOT out MATCHES "/velodyne_packets")
    message(FATAL_ERROR "a --packets-only log must have /velodyne_packets and no /lidar/points\n${out}")
  endif()
  # 6 s at 10 Hz: 60 scans, each decoded from its packets.
  execute_process(COMMAND ${LIDARLOOP} export ${WORKDIR}/run_1.mcap --pcd ${WORKDIR}/pcd
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT code EQUAL 0 OR NOT out MATCHES "exported     60 scans from /velodyne_packets")
    message(FATAL_ERROR "export --pcd of a --packets-only log exited ${code}\n${out}\n${err}")
  endif()
  message(STATUS "--packets-only: no /lidar/points in the log; replay and export decode the packets")
endif()
if(DATA)
  file(COPY ${DATA}/assets ${DATA}/maps DESTINATION ${WORKDIR}/data)
  set(vehicle ${WORKDIR}/data/assets/vehicle.yaml)
  file(READ ${vehicle} text)
  string(REGEX REPLACE "\nlf: [0-9.]+" "\nlf: 1.5" edited "${text}")
  string(REGEX REPLACE "\nsteering_ratio: [0-9.]+" "\nsteering_ratio: 14.0" edited "${edited}")
  if(NOT edited MATCHES "\nlf: 1.5 " OR NOT edited MATCHES "\nsteering_ratio: 14.0 ")
    message(FATAL_ERROR "could not edit ${vehicle}")
  endif()
  file(WRITE ${vehicle} "${edited}")
  replay_as_live(${WORKDIR}/replay_changed_assets "with assets/vehicle.yaml changed (lf 1.5, steering_ratio 14)"
                 LIDARLOOP_DATA=${WORKDIR}/data)
  message(STATUS "assets/vehicle.yaml changed: replay still gives the live run's estimates")
endif()
