#!/usr/bin/env bash
# A recording killed with SIGKILL loses at most the last second of log time. Records a complete run of
# a scenario, then the same run (same seed: the same messages, in the same order) killed at ten moments
# drawn from fixed seeds, recovers each killed log with `lidarloop recover`, and compares: the
# recovered messages must be the complete log's first ones, and every message the killed run had
# already written but recover did not get back must lie within 1 s of log time of the newest one it
# had written.
#
# What a killed run had written is bracketed from the complete log's write order, not guessed from
# clocks. `simulate --scan-every 1` writes each scan to a PLY file of its own before the recorder gets
# the scan, and the recorder writes one /lidar/points message per scan. With k PLY files on disk:
# - the run had begun scan k-1's PLY, so it had written every message before scan k-1's /lidar/points
#   (the lower bracket);
# - it had not begun scan k's PLY, so it had written nothing from scan k's /lidar/points on (the upper).
# A loss measured from the lower bracket's newest message that exceeds the limit is a certain breach:
# the test fails on it. The loss from the upper bracket is printed beside it; the two differ by about one
# scan period (the sensors' clocks run a few ms off the simulation's). The writer's exact bound is tested in-process (McapWriter.AKillLosesAtMost...).
#
# kill_recording.sh LIDARLOOP MCAP_LOG_TIMES SCENARIO WORKDIR [KILLS] [DURATION_S]
set -euo pipefail
lidarloop=$1 log_times=$2 scenario=$3 work=$4 kills=${5:-10} duration=${6:-3}
max_loss_ns=1000000000
scan_topic=/lidar/points

rm -rf "$work"
mkdir -p "$work"
simulate=("$lidarloop" simulate "$scenario" --duration "$duration" --scan-every 1)
seconds() { awk -v n="$1" 'BEGIN { printf "%.3f", n / 1e9 }'; }  # mawk's %d stops at 2^31: keep ns out of it

"${simulate[@]}" --record "$work/complete.mcap" --out "$work/complete" > "$work/complete.txt"
sim_wall_ms=$(awk '/^simulated/ { printf "%d", $5 * 1000 }' "$work/complete.txt")
"$log_times" "$work/complete.mcap" > "$work/complete_times.txt"
scans=$(ls "$work/complete/scans" | wc -l)
if [ "$(grep -c " $scan_topic\$" "$work/complete_times.txt")" -ne "$scans" ]; then
  echo "the complete log does not hold one $scan_topic message per scan ($scans PLY files)" >&2
  exit 1
fi
echo "complete run: $(wc -l < "$work/complete_times.txt") messages, $scans scans, ${duration} s of log simulated in ${sim_wall_ms} ms"

# written_before N: the number of messages in write order before scan N's /lidar/points (all of them
# when there is no scan N), and the newest log time among them.
written_before() {
  awk -v scan="$1" -v topic="$scan_topic" '
    $2 == topic && seen++ == scan { exit }
    { n++; if ($1 > newest) newest = $1 }
    END { printf "%d %.0f\n", n, newest }' "$work/complete_times.txt"
}
# loss RECOVERED WRITTEN NEWEST: the messages after the first RECOVERED (which recover got back) and
# among the first WRITTEN, whose newest log time is NEWEST: how many, and how far the oldest lies back.
loss() {
  awk -v from="$1" -v upto="$2" -v newest="$3" '
    NR > from && NR <= upto { if (!n++) oldest = $1 }
    END { printf "%d %.0f\n", n, n ? newest - oldest : 0 }' "$work/complete_times.txt"
}

worst_ns=0 worst_upper_ns=0 worst_messages=0
for seed in $(seq 1 "$kills"); do
  RANDOM=$seed
  : $RANDOM $RANDOM  # bash's first draws after seeding follow the seed closely: skip them
  delay_ms=$((sim_wall_ms * (5 + 90 * RANDOM / 32767) / 100))  # 5-95 % into the simulation
  rm -rf "$work/killed.mcap" "$work/killed" "$work/recovered.mcap"
  "${simulate[@]}" --record "$work/killed.mcap" --out "$work/killed" > /dev/null &
  pid=$!
  until [ -e "$work/killed/scans/scan_000000.ply" ] || ! kill -0 "$pid" 2> /dev/null; do sleep 0.01; done
  sleep "$(awk -v ms="$delay_ms" 'BEGIN { printf "%.3f", ms / 1000 }')"
  killed=yes
  kill -KILL "$pid" 2> /dev/null || killed="no, it had finished"
  wait "$pid" 2> /dev/null || true

  done_scans=$(ls "$work/killed/scans" | wc -l)
  if [ "$done_scans" -eq 0 ]; then
    echo "kill $seed: the run ended before its first scan" >&2
    exit 1
  fi
  read -r lower_n lower_ns < <(written_before $((done_scans - 1)))
  read -r upper_n upper_ns < <(written_before "$done_scans")
  "$lidarloop" recover "$work/killed.mcap" "$work/recovered.mcap" > /dev/null
  "$log_times" "$work/recovered.mcap" > "$work/recovered_times.txt"
  recovered=$(wc -l < "$work/recovered_times.txt")
  if ! cmp -s "$work/recovered_times.txt" <(head -n "$recovered" "$work/complete_times.txt"); then
    echo "kill $seed: the recovered messages are not the complete log's first $recovered" >&2
    exit 1
  fi
  read -r lost loss_ns < <(loss "$recovered" "$lower_n" "$lower_ns")
  read -r lost_upper loss_upper_ns < <(loss "$recovered" "$upper_n" "$upper_ns")
  printf 'kill %2d, %4d ms into the simulation (killed: %s): %2d scans done, newest message written at %s-%s s; recovered %5d messages, lost %4d-%4d (%s-%s s of log time)\n' \
    "$seed" "$delay_ms" "$killed" "$done_scans" "$(seconds "$lower_ns")" "$(seconds "$upper_ns")" "$recovered" \
    "$lost" "$lost_upper" "$(seconds "$loss_ns")" "$(seconds "$loss_upper_ns")"
  if [ "$loss_ns" -gt "$worst_ns" ]; then worst_ns=$loss_ns; fi
  if [ "$loss_upper_ns" -gt "$worst_upper_ns" ]; then worst_upper_ns=$loss_upper_ns; fi
  if [ "$lost" -gt "$worst_messages" ]; then worst_messages=$lost; fi
done
printf 'worst loss: at least %d messages, %s s of log time (at most %s s; limit %s s)\n' "$worst_messages" \
  "$(seconds "$worst_ns")" "$(seconds "$worst_upper_ns")" "$(seconds "$max_loss_ns")"
[ "$worst_ns" -le "$max_loss_ns" ]
