# A localizer says it is lost in time when a fault makes its inputs disagree with it: `lost` raised within
# the scenario's lost_within_s of the event and cleared afterwards, and every frame carries protection
# bounds. Used for the C++ and Python examples (examples/external/: they gate each fix on its innovation
# and say they are lost when three in a row disagree) on scenarios/gps_jump_parked.yaml (a 4 m multipath
# jump from 8 s to 16 s) and scenarios/kidnap_car.yaml (the car set down 3.8 m away at 8 s, which the
# fixes then show), and for the built-in localizer on cold_start_parked (the start). The run itself may
# fail the scenario's thresholds (exit 1): a CAN + GPS filter is metres off, and the built-in localizer's
# cold start between parked rows converges too late on about half the seeds (docs/scenarios.md).
# -DMAX_MISLEADING=N also fails a run with more misleading frames (integrity.misleading_frames) than N.
# -DLIDARLOOP=... -DSCENARIO=... -DMETHOD=... -DWORKDIR=... [-DEVENT="gps jump" (default), kidnap or start]
# [-DMAX_MISLEADING=N]
if(NOT DEFINED EVENT)
  set(EVENT "gps jump")
endif()
file(REMOVE_RECURSE ${WORKDIR})
execute_process(COMMAND ${LIDARLOOP} run ${SCENARIO} --method ${METHOD} --out ${WORKDIR}
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 300)
if(NOT code EQUAL 0 AND NOT code EQUAL 1)
  message(FATAL_ERROR "the example's run exited ${code}\n${out}\n${err}")
endif()
message(STATUS "${out}")
file(READ ${WORKDIR}/metrics.json metrics)
string(JSON bounded GET "${metrics}" integrity frames_with_bounds)
string(JSON awaiting GET "${metrics}" integrity frames_awaiting_alert)  # bounded too, counted apart
string(JSON frames GET "${metrics}" frames)
math(EXPR bounded "${bounded} + ${awaiting}")
if(NOT bounded EQUAL frames)
  message(FATAL_ERROR "${bounded} of ${frames} frames carry protection bounds: the example gives them with every pose")
endif()
if(DEFINED MAX_MISLEADING)
  string(JSON misleading GET "${metrics}" integrity misleading_frames)
  if(misleading GREATER MAX_MISLEADING)
    message(FATAL_ERROR "${misleading} misleading frames (at most ${MAX_MISLEADING})")
  endif()
endif()
string(JSON lost_within GET "${metrics}" thresholds recovery lost_within_s)
string(JSON events LENGTH "${metrics}" recovery)
math(EXPR last "${events} - 1")
set(jumps 0)
foreach(i RANGE ${last})
  string(JSON event GET "${metrics}" recovery ${i} event)
  if(NOT event STREQUAL EVENT)
    continue()
  endif()
  math(EXPR jumps "${jumps} + 1")
  string(JSON raised GET "${metrics}" recovery ${i} lost_raised_after_s)
  string(JSON cleared GET "${metrics}" recovery ${i} lost_cleared_after_s)
  # A null is not a number, so it fails these comparisons too.
  if(NOT raised GREATER_EQUAL 0 OR raised GREATER lost_within OR NOT cleared GREATER raised)
    message(FATAL_ERROR "the ${EVENT}: lost raised after ${raised} s (at most ${lost_within} s), cleared after "
                        "${cleared} s: expected raised in time and cleared after it")
  endif()
endforeach()
if(NOT jumps EQUAL 1)
  message(FATAL_ERROR "expected one ${EVENT} in metrics.json's recovery, found ${jumps}")
endif()
