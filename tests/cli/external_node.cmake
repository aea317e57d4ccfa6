# The Node.js example localizer (examples/external/node/localizer.mjs) in closed loop: it must pass the
# scenario's thresholds, and the estimates it wrote with --record (nav_msgs/msg/Odometry in an MCAP file
# written by @mcap/core) must score, with `lidarloop score` against the run's log, as the live run did.
# -DLIDARLOOP=... -DSCENARIO=... -DMETHOD=exec:... -DWORKDIR=...
file(REMOVE_RECURSE ${WORKDIR})
file(MAKE_DIRECTORY ${WORKDIR})
execute_process(COMMAND ${LIDARLOOP} run ${SCENARIO} --method ${METHOD} --record ${WORKDIR}/run.mcap --out ${WORKDIR}/live
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 240)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "the Node.js localizer's run exited ${code}\n${out}\n${err}")
endif()
message(STATUS "${out}")
