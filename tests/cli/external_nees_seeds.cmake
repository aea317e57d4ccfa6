# The C++ example's covariance over several seeds, in closed loop as the scenario runs (nees.cmake):
# each axis's mean NEES, averaged over the seeds' runs, within the band. One run is about one draw of
# the GPS bias; several are a test of the noise model rather than of one seed's luck.
# -DLIDARLOOP=... -DSCENARIO=... -DMETHOD=exec:... -DSEEDS=1;2;... -DWORKDIR=...
include(${CMAKE_CURRENT_LIST_DIR}/nees.cmake)
file(REMOVE_RECURSE ${WORKDIR})
set(metrics)
foreach(seed ${SEEDS})
  # --latency one_scan: the covariance is judged on a repeatable run (an exec: program's measured latency,
  # the default, follows the machine's load and so does the closed-loop drive).
  execute_process(COMMAND ${LIDARLOOP} run ${SCENARIO} --seed ${seed} --method ${METHOD} --latency one_scan
                          --out ${WORKDIR}/seed_${seed}
                  RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  # Exit 1 (a threshold failed) still has a metrics.json to judge the covariance by.
  if(NOT (code EQUAL 0 OR code EQUAL 1))
    message(FATAL_ERROR "run --seed ${seed} exited ${code}\n${out}\n${err}")
  endif()
  list(APPEND metrics ${WORKDIR}/seed_${seed}/metrics.json)
endforeach()
nees_over_seeds(${metrics})
