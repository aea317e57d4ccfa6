# The HDL-32E packets cross-check (label `node`): a short simulated drive recorded with --packets,
# exported with --pcap, then read by Foxglove's @foxglove/velodyne-cloud and the npm pcap-parser
# (velodyne_packets.mjs). Arguments: LIDARLOOP, NODE, SCRIPT, SCENARIO, WORKDIR.
function(run)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY ${WORKDIR} RESULT_VARIABLE code OUTPUT_VARIABLE out
                  ERROR_VARIABLE err TIMEOUT 300)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "failed (${code}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()

run(${LIDARLOOP} simulate ${SCENARIO} --duration 2 --out ${WORKDIR}/packets_run --record ${WORKDIR}/packets.mcap
    --packets)
run(${LIDARLOOP} info ${WORKDIR}/packets.mcap)
run(${LIDARLOOP} export ${WORKDIR}/packets.mcap --pcap ${WORKDIR}/packets.pcap)
run(${NODE} ${SCRIPT} ${WORKDIR}/packets.mcap ${WORKDIR}/packets.pcap)
