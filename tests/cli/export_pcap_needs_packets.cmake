# `export --pcap` on a log recorded without --packets: exit 2, and the message says how to record one.
# Arguments: CHECK (mcap_node_check, which writes a small log), LIDARLOOP, WORKDIR.
execute_process(COMMAND ${CHECK} write ${WORKDIR}/no_packets.mcap RESULT_VARIABLE code OUTPUT_QUIET)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "mcap_node_check write failed (${code})")
endif()
execute_process(COMMAND ${LIDARLOOP} export ${WORKDIR}/no_packets.mcap --pcap ${WORKDIR}/never.pcap
                RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
set(expected "no velodyne_msgs/msg/VelodyneScan messages on topic '/velodyne_packets': record the run with --record FILE.mcap --packets")
string(FIND "${out}${err}" "${expected}" found)
if(NOT code EQUAL 2 OR found EQUAL -1 OR EXISTS ${WORKDIR}/never.pcap)
  message(FATAL_ERROR "expected exit 2, '${expected}' and no file\ngot exit ${code}\n${out}\n${err}")
endif()
