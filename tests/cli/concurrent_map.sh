#!/usr/bin/env bash
# Processes sharing one map cache, as a sweep starts them: several `lidarloop map` at once on an empty
# cache must all succeed, exactly one of them build while the others wait and find its map, and leave a
# whole, readable map and no temporary folder. Then rebuilds (--force) racing with readers: all succeed
# and the map is whole again.
# usage: concurrent_map.sh LIDARLOOP WORLD_YAML WORKDIR [PROCESSES]
set -euo pipefail
lidarloop=$1 world=$2 work=$3 processes=${4:-4}
rm -rf "$work"
mkdir -p "$work/cache"
export LIDARLOOP_MAP_CACHE=$work/cache

fail() {
  echo "FAIL: $*" >&2
  for f in "$work"/*.txt; do echo "--- $f" >&2 && cat "$f" >&2; done
  exit 1
}

# Runs `lidarloop map WORLD` once per argument list given as "name:extra args", all at once.
run_at_once() {
  local pids=() names=()
  for job in "$@"; do
    local name=${job%%:*} extra=${job#*:}
    # One thread each: the test is about the cache, and the machine may be shared.
    # shellcheck disable=SC2086
    "$lidarloop" map "$world" --threads 1 $extra >"$work/$name.txt" 2>&1 &
    pids+=($!) names+=("$name")
  done
  for i in "${!pids[@]}"; do
    wait "${pids[$i]}" || fail "${names[$i]} exited $?"
  done
}

# The cache holds one map folder and its lock file, nothing else; the map is whole and readable.
check_cache() {
  local entries
  entries=$(cd "$work/cache" && ls -A)
  local maps=("$work"/cache/*/)
  [ ${#maps[@]} -eq 1 ] || fail "expected one map folder in the cache, found: $entries"
  local map=${maps[0]%/}
  [ "$(cd "$work/cache" && ls -A | sort | tr '\n' ' ')" = "$(basename "$map") $(basename "$map").lock " ] ||
    fail "expected only the map and its lock in the cache, found: $entries"
  for f in map.yaml curbs.geojson mean.png variance.png survey_error.png; do
    [ -s "$map/$f" ] || fail "$map/$f is missing or empty"
  done
  local tiles
  tiles=$(find "$map/tiles" -name '*.tile' | wc -l)
  [ "$tiles" -gt 0 ] || fail "$map/tiles holds no tiles"
  [ "$(grep -c '^  - \[' "$map/map.yaml")" -eq "$tiles" ] || fail "map.yaml does not list the $tiles tiles"
  # Every tile read and checked (CRC) by the map benchmark's lookups along the road.
  "$lidarloop" bench map --world "$world" --map "$map" >"$work/bench.txt" 2>&1 || fail "bench map on $map failed"
  grep -q '"cells_with_data"' "$work/bench.txt" || fail "bench map printed no result"
}

jobs=()
for i in $(seq 1 "$processes"); do jobs+=("first_$i:"); done
run_at_once "${jobs[@]}"
built=$(grep -l '(built)' "$work"/first_*.txt | wc -l)
found=$(grep -l '(found in the cache)' "$work"/first_*.txt | wc -l)
[ "$built" -eq 1 ] || fail "$built of $processes processes built the map (expected exactly 1)"
[ "$found" -eq $((processes - 1)) ] || fail "$found of $processes processes found the map (expected $((processes - 1)))"
check_cache
# The map's bytes: header, tiles and curbs (the rebuild must give the same).
map_digest() { (cd "$work"/cache/*/ && find . -name '*.tile' -o -name map.yaml -o -name curbs.geojson | sort | xargs md5sum) | md5sum; }
first=$(map_digest)

run_at_once "force_1:--force" "force_2:--force" "read_1:" "read_2:"
for name in force_1 force_2; do grep -q '(built)' "$work/$name.txt" || fail "$name did not rebuild"; done
check_cache
[ "$(map_digest)" = "$first" ] || fail "the rebuilt map differs from the first"
echo "$processes processes at once: 1 built, $((processes - 1)) found its map; 2 rebuilds racing 2 readers: ok"
