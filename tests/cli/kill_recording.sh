#!/usr/bin/env bash
# A recording killed with SIGKILL loses at most the last second of log time. Records a complete run of
# a scenario, then the same run (same seed: the same messages) killed at ten moments drawn from fixed
# seeds, recovers each killed log with `lidarloop recover`, and compares: the recovered messages must
# be the complete log's first ones, and every message the killed run had written but recover did not
# get back must lie within 1 s of log time of the newest one it had written.
#
# How far a killed run got: `simulate` prints its simulated time on a terminal after every step, so it
# runs on a pseudo-terminal (script(1)) and the last time printed, plus its rounding, bounds the
# newest message written from above: the loss figures are upper bounds.
#
# kill_recording.sh LIDARLOOP MCAP_LOG_TIMES SCENARIO WORKDIR [KILLS] [DURATION_S]
set -euo pipefail
lidarloop=$1 log_times=$2 scenario=$3 work=$4 kills=${5:-10} duration=${6:-3}
max_loss_ns=1000000000
# %.1f s on the progress line: the time printed is at most 0.05 s behind, plus one step of 1 ms.
progress_slack_ns=51000000

rm -rf "$work"
mkdir -p "$work"
simulate=("$lidarloop" simulate "$scenario" --duration "$duration" --scan-every 0)

start=$(date +%s%N)
"${simulate[@]}" --record "$work/complete.mcap" --out "$work/complete" > /dev/null
wall_ns=$(($(date +%s%N) - start))
"$log_times" "$work/complete.mcap" > "$work/complete.txt"
echo "complete run: $(wc -l < "$work/complete.txt") messages, ${duration} s of log in $((wall_ns / 1000000)) ms"

worst_ns=0 worst_messages=0
for seed in $(seq 1 "$kills"); do
  RANDOM=$seed
  delay_ns=$((wall_ns * (20 + 75 * RANDOM / 32767) / 100))  # 20-95 % of the complete run's wall time
  rm -rf "$work/killed.mcap" "$work/killed" "$work/pid" "$work/recovered.mcap"
  script -qfec "echo \$\$ > '$work/pid'; exec ${simulate[*]} --record '$work/killed.mcap' --out '$work/killed'" \
    /dev/null < /dev/null > "$work/progress.txt" &
  script_pid=$!
  sleep "$(awk -v ns="$delay_ns" 'BEGIN { printf "%.3f", ns / 1e9 }')"
  killed=yes
  kill -KILL "$(cat "$work/pid")" 2> /dev/null || killed="no (it had finished)"
  wait "$script_pid" || true

  newest=$(grep -ao '[0-9.]* of [0-9.]* s' "$work/progress.txt" | tail -1 | cut -d' ' -f1)
  [ -n "$newest" ] || newest=0
  newest_ns=$(awk -v s="$newest" -v slack="$progress_slack_ns" 'BEGIN { printf "%d", s * 1e9 + slack }')
  recovered=0
  if [ -e "$work/killed.mcap" ]; then
    "$lidarloop" recover "$work/killed.mcap" "$work/recovered.mcap" > /dev/null
    "$log_times" "$work/recovered.mcap" > "$work/recovered.txt"
    recovered=$(wc -l < "$work/recovered.txt")
    if ! cmp -s "$work/recovered.txt" <(head -n "$recovered" "$work/complete.txt"); then
      echo "kill $seed: the recovered messages are not the complete log's first $recovered" >&2
      exit 1
    fi
  fi
  # Messages the killed run had written (log time up to the newest) that recover did not get back.
  read -r lost loss_ns < <(awk -v from="$recovered" -v newest="$newest_ns" '
    NR > from && $1 <= newest { if (!n++) oldest = $1 }
    END { printf "%d %d\n", n, n ? newest - oldest : 0 }' "$work/complete.txt")
  printf 'kill %2d after %5d ms (killed: %s): newest log time <= %.3f s, recovered %d messages, lost %d (%.3f s of log time)\n' \
    "$seed" $((delay_ns / 1000000)) "$killed" "$(awk -v n="$newest_ns" 'BEGIN { print n / 1e9 }')" "$recovered" \
    "$lost" "$(awk -v n="$loss_ns" 'BEGIN { print n / 1e9 }')"
  [ "$loss_ns" -gt "$worst_ns" ] && worst_ns=$loss_ns
  [ "$lost" -gt "$worst_messages" ] && worst_messages=$lost
done
printf 'worst loss: %d messages, %.3f s of log time (limit %.3f s)\n' "$worst_messages" \
  "$(awk -v n="$worst_ns" 'BEGIN { print n / 1e9 }')" "$(awk -v n="$max_loss_ns" 'BEGIN { print n / 1e9 }')"
[ "$worst_ns" -le "$max_loss_ns" ]
