# The HDL-32E packets cross-check (label `node`): a short simulated drive recorded with --packets,
# exported with --pcap, then read by Foxglove's @foxglove/velodyne-cloud and the npm pcap-parser
# (velodyne_packets.mjs). Arguments: LIDARLOOP, NODE, SCRIPT, SCENARIO, WORKDIR.
include(${CMAKE_CURRENT_LIST_DIR}/run_step.cmake)

run(${LIDARLOOP} simulate ${SCENARIO} --duration 2 --out ${WORKDIR}/packets_run --record ${WORKDIR}/packets.mcap
    --packets)
message(STATUS "${out}")
run(${LIDARLOOP} info ${WORKDIR}/packets.mcap)
message(STATUS "${out}")
run(${LIDARLOOP} export ${WORKDIR}/packets.mcap --pcap ${WORKDIR}/packets.pcap)
message(STATUS "${out}")
run(${NODE} ${SCRIPT} ${WORKDIR}/packets.mcap ${WORKDIR}/packets.pcap)
message(STATUS "${out}")
