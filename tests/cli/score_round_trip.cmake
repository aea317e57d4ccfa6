# The round trip of issue 17: `run --record` with the proposed method, `export --tum` of the estimate,
# `score` of that TUM against the log must give the live run's metrics.json bit for bit: every line
# of the file but the three latency lines (a TUM file has no latency: score writes null) is compared
# as text, and nlohmann writes each double in the shortest form that reads back as it, so equal
# text is equal bits. The log's own /localizer/odometry scored as an MCAP estimate must give the same.
# Then the bad inputs, each exit 2 with a one-line error naming the file and the problem, and the
# thresholds from the command line.
# -DLIDARLOOP=... -DSCENARIO=... -DWORKDIR=...
file(REMOVE_RECURSE ${WORKDIR})
file(MAKE_DIRECTORY ${WORKDIR})
set(log ${WORKDIR}/run.mcap)

# Runs lidarloop with ARGN; fails unless it exits `expected` with `expected_output` in its output.
function(lidarloop expected expected_output)
  execute_process(COMMAND ${LIDARLOOP} ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(FIND "${out}${err}" "${expected_output}" found)
  if(NOT code EQUAL expected OR found EQUAL -1)
    message(FATAL_ERROR "lidarloop ${ARGN}\nexpected exit ${expected} and output containing '${expected_output}'\n"
                        "got exit ${code}\nstdout: ${out}\nstderr: ${err}")
  endif()
  if(expected EQUAL 2)  # a bad input: one line, nothing on stdout
    string(STRIP "${err}" err)
    string(FIND "${err}" "\n" newline)
    if(NOT out STREQUAL "" OR NOT newline EQUAL -1)
      message(FATAL_ERROR "lidarloop ${ARGN}\nexpected a one-line error, got\nstdout: ${out}\nstderr: ${err}")
    endif()
  endif()
endfunction()

# metrics.json without its latency lines, nor the lines of what an estimate file may not carry: the
# covariance (a TUM file has none: its consistency is null), the protection bounds and `lost` (neither
# file has them: integrity counts no bounds, recovery no `lost`), and the map observations the live
# localizer took (the whole `map_observations` block: only a live run or a replay has them).
function(accuracy_lines file result)
  file(STRINGS ${file} all)
  set(lines "")
  set(depth 0)
  foreach(line IN LISTS all)
    if(depth GREATER 0 OR line MATCHES "\"map_observations\"")
      string(REGEX MATCHALL "[{]" opens "${line}")
      string(REGEX MATCHALL "[}]" closes "${line}")
      list(LENGTH opens o)
      list(LENGTH closes c)
      math(EXPR depth "${depth} + ${o} - ${c}")
      continue()
    endif()
    list(APPEND lines "${line}")
  endforeach()
  list(FILTER lines EXCLUDE REGEX
       "\"(latency_|frames_with_covariance|mean_nees_|beyond_3_sigma_|frames_with_bounds|misleading_|availability|lost_raised_after_s|lost_cleared_after_s)")
  set(${result} "${lines}" PARENT_SCOPE)
endfunction()

function(expect_same_metrics live scored what)
  accuracy_lines(${live} a)
  accuracy_lines(${scored} b)
  if(NOT a STREQUAL b)
    message(FATAL_ERROR "${what}: metrics.json differs from the live run's\nlive:   ${a}\nscored: ${b}")
  endif()
  file(READ ${scored} text)
  foreach(key latency_p50_ms latency_p99_ms latency_max_ms latency_first_scan_ms)
    string(JSON value TYPE "${text}" ${key})
    if(NOT value STREQUAL "NULL")
      message(FATAL_ERROR "${what}: ${key} should be null (no latency in the estimate file), is ${value}")
    endif()
  endforeach()
endfunction()

lidarloop(0 "result     PASS" run ${SCENARIO} --method proposed --duration 6 --record ${log} --out ${WORKDIR}/live)
lidarloop(0 "exported" export ${log} --tum ${WORKDIR}/est.tum)
lidarloop(0 "result     PASS" score ${log} --estimate ${WORKDIR}/est.tum --method proposed --out ${WORKDIR}/tum)
expect_same_metrics(${WORKDIR}/live/metrics.json ${WORKDIR}/tum/metrics.json "TUM")
# The scoring reference is drawn from the truth and the seed where the run is scored: `score` of the
# log draws the live run's, byte for byte.
file(SHA256 ${WORKDIR}/live/reference.tum live_reference)
file(SHA256 ${WORKDIR}/tum/reference.tum scored_reference)
if(NOT live_reference STREQUAL scored_reference)
  message(FATAL_ERROR "reference.tum of score differs from the live run's")
endif()
lidarloop(0 "MCAP /localizer/odometry (nav_msgs/msg/Odometry)" score ${log} --estimate ${log}
          --topic /localizer/odometry --method proposed --out ${WORKDIR}/mcap)
expect_same_metrics(${WORKDIR}/live/metrics.json ${WORKDIR}/mcap/metrics.json "MCAP")
foreach(file errors.csv estimate.tum truth.tum junit.xml errors.png trajectory.png worst_frame.png)
  if(NOT EXISTS ${WORKDIR}/tum/${file})
    message(FATAL_ERROR "score did not write ${file}")
  endif()
endforeach()

# Thresholds from the command line override the scenario's: exit 1 when one fails.
lidarloop(1 "FAILED     coverage" score ${log} --estimate ${WORKDIR}/est.tum --threshold min_coverage=0.999
          --out ${WORKDIR}/strict)
file(WRITE ${WORKDIR}/pass.yaml "pass: {lateral_rmse_m: 0.0001}\n")
lidarloop(1 "FAILED     lateral RMSE" score ${log} --estimate ${WORKDIR}/est.tum --pass ${WORKDIR}/pass.yaml
          --out ${WORKDIR}/strict)
lidarloop(0 "result     PASS" score ${log} --estimate ${WORKDIR}/est.tum --pass ${WORKDIR}/pass.yaml
          --threshold lateral_rmse_m=1 --out ${WORKDIR}/strict)

# Bad input: exit 2 and one line naming the file and the problem.
file(WRITE ${WORKDIR}/short_line.tum "# t x y z qx qy qz qw\n1.0 1 2 0 0 0 0 1\n1.1 1 2 0 0 0 1\n")
lidarloop(2 "short_line.tum:3: expected 8 numbers" score ${log} --estimate ${WORKDIR}/short_line.tum)
file(WRITE ${WORKDIR}/backwards.tum "1.0 1 2 0 0 0 0 1\n0.9 1 2 0 0 0 0 1\n")
lidarloop(2 "backwards.tum:2: time stamp 0.900000000 s is not after" score ${log} --estimate ${WORKDIR}/backwards.tum)
file(WRITE ${WORKDIR}/nan.tum "1.0 1 2 0 0 0 0 1\n1.1 nan 2 0 0 0 0 1\n")
lidarloop(2 "nan.tum:2: 'nan' is not a finite number" score ${log} --estimate ${WORKDIR}/nan.tum)
file(WRITE ${WORKDIR}/empty.tum "")
lidarloop(2 "empty.tum: no poses" score ${log} --estimate ${WORKDIR}/empty.tum)
lidarloop(2 "run.mcap: no nav_msgs/msg/Odometry or geometry_msgs/msg/PoseWithCovarianceStamped on topic '/pose'"
          score ${log} --estimate ${log} --topic /pose)
lidarloop(2 "run.mcap: several nav_msgs/msg/Odometry or geometry_msgs/msg/PoseWithCovarianceStamped topics"
          score ${log} --estimate ${log})
file(WRITE ${WORKDIR}/late.tum "100.0 1 2 0 0 0 0 1\n101.0 1 2 0 0 0 0 1\n")
lidarloop(2 "late.tum: every estimate (t = 100.000000000 to 101.000000000 s) lies outside the ground truth"
          score ${log} --estimate ${WORKDIR}/late.tum)
lidarloop(2 "bad_syntax.yaml: not an MCAP file" score ${BAD}/bad_syntax.yaml --estimate ${WORKDIR}/est.tum)
lidarloop(2 "--estimate FILE is required" score ${log})
lidarloop(2 "unknown key 'lateral'" score ${log} --estimate ${WORKDIR}/est.tum --threshold lateral=1)
message(STATUS "run -> export --tum -> score: metrics.json identical but for latency (null); bad inputs exit 2")
