# The Node.js example localizer (examples/external/node/localizer.mjs) in closed loop: it must pass the
# scenario's thresholds, and the estimates it wrote with --record (nav_msgs/msg/Odometry in an MCAP file
# written by @mcap/core) must score, with `lidarloop score` against the run's log, as the live run did.
# Its covariance must be honest (nees.cmake).
# -DLIDARLOOP=... -DSCENARIO=... -DMETHOD=exec:... -DWORKDIR=...
include(${CMAKE_CURRENT_LIST_DIR}/nees.cmake)
file(REMOVE_RECURSE ${WORKDIR})
file(MAKE_DIRECTORY ${WORKDIR})
# --latency one_scan: the covariance is judged on a repeatable run (an exec: program's measured latency,
# the default, follows the machine's load and so does the closed-loop drive). --deadline-ms 1000: this
# checks the protocol and the covariance, not the deadline (external_fails_sleep does); on a loaded
# two-core machine Node.js once took more than the default 100 ms over a scan.
execute_process(COMMAND ${LIDARLOOP} run ${SCENARIO} --method ${METHOD} --latency one_scan --deadline-ms 1000
                        --record ${WORKDIR}/run.mcap
                        --out ${WORKDIR}/live
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 240)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "the Node.js localizer's run exited ${code}\n${out}\n${err}")
endif()
message(STATUS "${out}")
nees_one_run(${WORKDIR}/live/metrics.json)
execute_process(COMMAND ${LIDARLOOP} score ${WORKDIR}/run.mcap --estimate ${WORKDIR}/estimates.mcap
                        --topic /localizer/odometry --out ${WORKDIR}/score
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "score of the Node.js localizer's Odometry exited ${code}\n${out}\n${err}")
endif()
# Positions travel as the same float64 both ways, so they score identically; the yaw is JavaScript's
# sin/cos in the file against C++'s in the live run, equal to about 1e-15, so only its leading digits.
file(READ ${WORKDIR}/live/metrics.json live)
file(READ ${WORKDIR}/score/metrics.json scored)
foreach(key frames settling_frames lateral_rmse_m longitudinal_rmse_m position_rmse_m max_position_error_m coverage pass)
  string(JSON a GET "${live}" ${key})
  string(JSON b GET "${scored}" ${key})
  if(NOT a STREQUAL b)
    message(FATAL_ERROR "metrics.json ${key}: live ${a}, scored from the Node.js Odometry ${b}")
  endif()
endforeach()
string(JSON a GET "${live}" heading_rmse_deg)
string(JSON b GET "${scored}" heading_rmse_deg)
string(SUBSTRING "${a}" 0 10 a)
string(SUBSTRING "${b}" 0 10 b)
if(NOT a STREQUAL b)
  message(FATAL_ERROR "metrics.json heading_rmse_deg: live ${a}..., scored from the Node.js Odometry ${b}...")
endif()
message(STATUS "score of the Node.js localizer's Odometry MCAP: the live run's metrics")
