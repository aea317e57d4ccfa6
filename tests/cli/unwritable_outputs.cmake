# Outputs that cannot be written fail cleanly and early: exit 2 and a single line naming the path,
# never an internal error, and for `run` before the map is opened (so no map is needed here).
# -DLIDARLOOP=... -DSCENARIO=... -DSWEEP=... -DWORKDIR=...
file(REMOVE_RECURSE ${WORKDIR})
file(MAKE_DIRECTORY ${WORKDIR})

# A short log to export from.
execute_process(COMMAND ${LIDARLOOP} simulate ${SCENARIO} --duration 0.5 --scan-every 0 --out ${WORKDIR}/sim
                        --record ${WORKDIR}/short.mcap
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "simulate exited ${code}\n${out}\n${err}")
endif()

# expect_clean_failure(PATH ARGS...): `lidarloop ARGS` exits 2 with one line on stderr that names PATH.
function(expect_clean_failure path)
  execute_process(COMMAND ${LIDARLOOP} ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err
                  TIMEOUT 120)
  string(FIND "${err}" "${path}" named)
  string(REGEX MATCHALL "\n" lines "${err}")
  list(LENGTH lines line_count)
  if(NOT code EQUAL 2 OR named EQUAL -1 OR NOT line_count EQUAL 1 OR NOT err MATCHES "^lidarloop: error: ")
    message(FATAL_ERROR "lidarloop ${ARGN}: expected exit 2 and one error line naming ${path}\n"
                        "got exit ${code}\nstdout: ${out}\nstderr: ${err}")
  endif()
  message(STATUS "${err}")
endfunction()

set(run run ${SCENARIO} --duration 1)
expect_clean_failure(/proc/nope ${run} --out /proc/nope)
expect_clean_failure(/sys/kernel/nope ${run} --out /sys/kernel/nope/results)
expect_clean_failure(/proc/nope ${run} --out ${WORKDIR}/run --record /proc/nope/run.mcap)
expect_clean_failure(${WORKDIR} ${run} --out ${WORKDIR}/run --record ${WORKDIR})
expect_clean_failure(/dev/full ${run} --out ${WORKDIR}/run --record /dev/full)
expect_clean_failure(/dev/full simulate ${SCENARIO} --duration 0.5 --out ${WORKDIR}/sim --record /dev/full)
expect_clean_failure(/proc/nope simulate ${SCENARIO} --duration 0.5 --out /proc/nope)
expect_clean_failure(/dev/full export ${WORKDIR}/short.mcap --tum /dev/full)
expect_clean_failure(/proc/nope export ${WORKDIR}/short.mcap --pcd /proc/nope)
expect_clean_failure(/proc/nope replay ${WORKDIR}/short.mcap --out /proc/nope)
expect_clean_failure(/dev/full recover ${WORKDIR}/short.mcap /dev/full)
expect_clean_failure(/proc/nope sweep ${SWEEP} --out /proc/nope)
