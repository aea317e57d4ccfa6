# Record a run at one thread and at two: the logs must be byte-identical. Replay the log: the estimates
# and ground truth must be the live run's exactly, and so must every accuracy figure of metrics.json
# (latency is wall time and is not compared), the curb occlusion included (replay reads it from the log).
# -DLIDARLOOP=... -DSCENARIO=... -DWORKDIR=... [-DMETHOD=...: the run's method, recorded in the log]
file(REMOVE_RECURSE ${WORKDIR})
file(MAKE_DIRECTORY ${WORKDIR})
set(method)
if(METHOD)
  set(method --method ${METHOD})
endif()
foreach(threads 1 2)
  execute_process(COMMAND ${LIDARLOOP} run ${SCENARIO} --duration 6 --threads ${threads} ${method}
                          --record ${WORKDIR}/run_${threads}.mcap --out ${WORKDIR}/live_${threads}
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
execute_process(COMMAND ${LIDARLOOP} replay ${WORKDIR}/run_1.mcap --out ${WORKDIR}/replay
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "replay exited ${code}\n${out}\n${err}")
endif()
foreach(file estimate.tum truth.tum)
  execute_process(COMMAND ${CMAKE_COMMAND} -E compare_files ${WORKDIR}/live_1/${file} ${WORKDIR}/replay/${file}
                  RESULT_VARIABLE differ)
  if(differ)
    message(FATAL_ERROR "replay's ${file} differs from the live run's")
  endif()
endforeach()
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
