# An exec: program's `lost` and protection bounds are scored as a built-in method's, with known truth:
# tests/external/integrity_localizer.cpp answers 20 estimates whose claims cycle through
# misleading-and-available, bounded-but-unavailable, lost, and no bounds (5 of each), on a scenario that
# scores every estimate (tests/data/external_integrity.yaml). The live run, `score` of the log's own
# /localizer/odometry and /localizer/status, and `replay` of the log with the same program must all
# give exactly: 20 frames, 15 with bounds, 5 misleading, availability 0.25, and `lost` raised at the
# third estimate and cleared at the fourth (0.1 s later).
# -DLIDARLOOP=... -DSCENARIO=... -DMETHOD=exec:... -DWORKDIR=...
file(REMOVE_RECURSE ${WORKDIR})
file(MAKE_DIRECTORY ${WORKDIR})
set(log ${WORKDIR}/run.mcap)
set(integrity_line "misleading 5 of 15 frames with bounds (33.33%), available 25.0%")

# Runs lidarloop with ARGN; fails unless it exits 0 with `expected_output` on stdout.
function(lidarloop expected_output)
  execute_process(COMMAND ${LIDARLOOP} ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err
                  TIMEOUT 120)
  string(FIND "${out}" "${expected_output}" found)
  if(NOT code EQUAL 0 OR found EQUAL -1)
    message(FATAL_ERROR "lidarloop ${ARGN}\nexpected exit 0 and '${expected_output}'\ngot exit ${code}\n"
                        "stdout: ${out}\nstderr: ${err}")
  endif()
  message(STATUS "${out}")
endfunction()

function(expect_value json what expected)
  string(JSON value GET "${json}" ${ARGN})
  if(NOT value EQUAL expected)
    message(FATAL_ERROR "${what}: ${ARGN} is ${value}, expected ${expected}")
  endif()
endfunction()

function(check_metrics dir what)
  file(READ ${dir}/metrics.json metrics)
  expect_value("${metrics}" ${what} 20 frames)
  expect_value("${metrics}" ${what} 15 integrity frames_with_bounds)
  expect_value("${metrics}" ${what} 5 integrity misleading_frames)
  expect_value("${metrics}" ${what} 0 integrity frames_awaiting_alert)
  string(JSON availability GET "${metrics}" integrity availability)
  if(NOT availability STREQUAL "0.25")
    message(FATAL_ERROR "${what}: availability ${availability}, expected 0.25")
  endif()
  string(JSON event GET "${metrics}" recovery 0 event)
  string(JSON raised GET "${metrics}" recovery 0 lost_raised_after_s)
  string(JSON cleared GET "${metrics}" recovery 0 lost_cleared_after_s)
  # A null is not a number, so it fails these comparisons too (if() compares numbers as doubles).
  if(NOT event STREQUAL "start" OR NOT raised GREATER 0 OR NOT cleared GREATER raised)
    message(FATAL_ERROR "${what}: the start's lost raised after ${raised} s, cleared after ${cleared} s: expected "
                        "0 < raised < cleared")
  endif()
endfunction()

lidarloop("${integrity_line}" run ${SCENARIO} --method ${METHOD} --record ${log} --out ${WORKDIR}/live)
check_metrics(${WORKDIR}/live "run")
lidarloop("${integrity_line}" score ${log} --estimate ${log} --topic /localizer/odometry --method mine
          --out ${WORKDIR}/scored)
check_metrics(${WORKDIR}/scored "score of the log")
# replay prints no integrity line; it compares each scan's status (lost, bounds) with the log's.
lidarloop("the localizer's status matched the log's at all 30 scans" replay ${log} --method ${METHOD}
          --out ${WORKDIR}/replayed)
check_metrics(${WORKDIR}/replayed "replay")
