# A localizer program that breaks the protocol (tests/external/misbehaving_localizer.cpp): the run must
# end with exit 2 and a message naming the scan (EXPECT_OUTPUT), within seconds, and the log recorded
# up to then must be a complete, readable MCAP file. With EXPECT_RESULTS in the environment (a program
# that fails only after its last answer), the run's results must be written and marked failed.
# -DLIDARLOOP=... -DSCENARIO=... -DMETHOD=exec:... -DEXPECT_OUTPUT=... -DWORKDIR=...
file(REMOVE_RECURSE ${WORKDIR})
file(MAKE_DIRECTORY ${WORKDIR})
execute_process(COMMAND ${LIDARLOOP} run ${SCENARIO} --duration 3 --method ${METHOD} --record ${WORKDIR}/run.mcap
                        --out ${WORKDIR}/out
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
string(FIND "${out}${err}" "${EXPECT_OUTPUT}" found)
if(NOT code EQUAL 2 OR found EQUAL -1)
  message(FATAL_ERROR "expected exit 2 and '${EXPECT_OUTPUT}'\ngot exit ${code}\nstdout: ${out}\nstderr: ${err}")
endif()
execute_process(COMMAND ${LIDARLOOP} info ${WORKDIR}/run.mcap RESULT_VARIABLE code OUTPUT_VARIABLE info
                ERROR_VARIABLE info_err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "the log of the failed run is not readable (info exited ${code}):\n${info}\n${info_err}")
endif()
if(DEFINED ENV{EXPECT_RESULTS})
  if(NOT EXISTS ${WORKDIR}/out/metrics.json)
    message(FATAL_ERROR "the program failed after its last answer, and the run's results were not written")
  endif()
  file(READ ${WORKDIR}/out/metrics.json metrics)
  string(JSON pass GET "${metrics}" pass)
  string(JSON failures GET "${metrics}" failures)
  string(FIND "${failures}" "${EXPECT_OUTPUT}" named)
  if(pass OR named EQUAL -1)
    message(FATAL_ERROR "metrics.json must say the run failed, with '${EXPECT_OUTPUT}': pass ${pass}, failures ${failures}")
  endif()
endif()
message(STATUS "${err}")
