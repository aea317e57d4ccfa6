#!/usr/bin/env bash
# A recording killed with SIGKILL loses at most the last second of log time. Records a complete run of
# a scenario, then the same run (same seed: the same messages) killed at ten moments drawn from fixed
# seeds, recovers each killed log with `lidarloop recover`, and compares: the recovered messages must
# be the complete log's first ones, and every message the killed run had already written but recover
# did not get back must lie within 1 s of log time of the newest one it had written.
#
# How far a killed run got: `simulate --scan-every 1` writes each scan to a PLY file of its own the
# moment the scan is complete (before the recorder gets it). With k PLY files on disk the run had not
# completed scan k: nothing it wrote is newer than scan k's end, the stamp of scan k (read from the
# complete run's PLY) plus one scan period plus a margin for the sensor clocks. So the loss measured
# is an upper bound, by up to one scan period.
#
# kill_recording.sh LIDARLOOP MCAP_LOG_TIMES SCENARIO WORKDIR [KILLS] [DURATION_S]
set -euo pipefail
lidarloop=$1 log_times=$2 scenario=$3 work=$4 kills=${5:-10} duration=${6:-3}
max_loss_ns=1000000000
clock_margin_ns=20000000  # the LiDAR's and CAN's clocks run a few ms off the simulation's

rm -rf "$work"
mkdir -p "$work"
simulate=("$lidarloop" simulate "$scenario" --duration "$duration" --scan-every 1)
scan_stamp() { grep -a -m1 '^comment stamp_ns ' "$1" | cut -d' ' -f3; }

"${simulate[@]}" --record "$work/complete.mcap" --out "$work/complete" > "$work/complete.txt"
sim_wall_ms=$(awk '/^simulated/ { printf "%d", $5 * 1000 }' "$work/complete.txt")
"$log_times" "$work/complete.mcap" > "$work/complete_times.txt"
scans=$(ls "$work/complete/scans" | wc -l)
period_ns=$(($(scan_stamp "$work/complete/scans/scan_000001.ply") - $(scan_stamp "$work/complete/scans/scan_000000.ply")))
echo "complete run: $(wc -l < "$work/complete_times.txt") messages, $scans scans, ${duration} s of log simulated in ${sim_wall_ms} ms"

worst_ns=0 worst_messages=0
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
  if [ "$done_scans" -ge "$scans" ]; then
    newest_ns=$(awk -v d="$duration" 'BEGIN { printf "%d", d * 1e9 }')
  else
    next=$(printf '%s/complete/scans/scan_%06d.ply' "$work" "$done_scans")
    newest_ns=$(($(scan_stamp "$next") + period_ns + clock_margin_ns))
  fi
  "$lidarloop" recover "$work/killed.mcap" "$work/recovered.mcap" > /dev/null
  "$log_times" "$work/recovered.mcap" > "$work/recovered_times.txt"
  recovered=$(wc -l < "$work/recovered_times.txt")
  if ! cmp -s "$work/recovered_times.txt" <(head -n "$recovered" "$work/complete_times.txt"); then
    echo "kill $seed: the recovered messages are not the complete log's first $recovered" >&2
    exit 1
  fi
  # Messages the killed run may have written (log time up to the newest) that recover did not get back.
  read -r lost loss_ns < <(awk -v from="$recovered" -v newest="$newest_ns" '
    NR > from && $1 <= newest { if (!n++) oldest = $1 }
    END { printf "%d %d\n", n, n ? newest - oldest : 0 }' "$work/complete_times.txt")
  printf 'kill %2d, %4d ms into the simulation (killed: %s): %2d scans done, newest log time <= %.3f s; recovered %5d messages, lost %4d (%.3f s of log time)\n' \
    "$seed" "$delay_ms" "$killed" "$done_scans" "$(awk -v n="$newest_ns" 'BEGIN { print n / 1e9 }')" "$recovered" \
    "$lost" "$(awk -v n="$loss_ns" 'BEGIN { print n / 1e9 }')"
  if [ "$loss_ns" -gt "$worst_ns" ]; then worst_ns=$loss_ns; fi
  if [ "$lost" -gt "$worst_messages" ]; then worst_messages=$lost; fi
done
printf 'worst loss: %d messages, %.3f s of log time (limit %.3f s)\n' "$worst_messages" \
  "$(awk -v n="$worst_ns" 'BEGIN { print n / 1e9 }')" "$(awk -v n="$max_loss_ns" 'BEGIN { print n / 1e9 }')"
[ "$worst_ns" -le "$max_loss_ns" ]
