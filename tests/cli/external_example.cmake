# A shipped example localizer (examples/external/) in closed loop: it must pass the scenario's
# thresholds, and its covariance must be honest (nees.cmake: the position's and the heading's mean NEES
# within the band on this run).
# -DLIDARLOOP=... -DSCENARIO=... -DMETHOD=exec:... -DWORKDIR=...
include(${CMAKE_CURRENT_LIST_DIR}/nees.cmake)
file(REMOVE_RECURSE ${WORKDIR})
# --latency one_scan: the covariance is judged on a repeatable run (an exec: program's measured latency,
# the default, follows the machine's load and so does the closed-loop drive).
execute_process(COMMAND ${LIDARLOOP} run ${SCENARIO} --method ${METHOD} --latency one_scan --out ${WORKDIR}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 240)
if(NOT code EQUAL 0 OR NOT out MATCHES "result     PASS")
  message(FATAL_ERROR "the example's run exited ${code}\n${out}\n${err}")
endif()
message(STATUS "${out}")
nees_one_run(${WORKDIR}/metrics.json)
