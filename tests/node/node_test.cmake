# The Node.js cross-check, run by CTest (label `node`): the C++ writer records the synthetic run,
# Foxglove's libraries read it back (read_mcap.mjs), and the C++ side compares what they found with
# what was written. Arguments: CHECK (mcap_node_check), NODE, SCRIPT (read_mcap.mjs), WORKDIR.
include(${CMAKE_CURRENT_LIST_DIR}/run_step.cmake)

run(${CHECK} write ${WORKDIR}/node_check.mcap)
message(STATUS "${out}")
run(${NODE} ${SCRIPT} ${WORKDIR}/node_check.mcap)
file(WRITE ${WORKDIR}/node_check.json "${out}")
run(${CHECK} compare ${WORKDIR}/node_check.mcap ${WORKDIR}/node_check.json)
message(STATUS "${out}")
