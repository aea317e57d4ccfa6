#!/usr/bin/env bash
# The two quick-start commands of the README.
#   tools/quickstart.sh run    install what is missing, build, run the main job
#   tools/quickstart.sh test   install what is missing, build, run every test (also under ASan + UBSan)
set -euo pipefail
cd "$(dirname "$0")/.."

what=${1:-}
case "$what" in run|test) ;; *) echo "usage: tools/quickstart.sh run|test" >&2; exit 2 ;; esac

tools/install_deps.sh
jobs=$(nproc)
build() {  # build DIR [cmake options...]
  local dir=$1; shift
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
  cmake --build "$dir" -j "$jobs"
}

if [ "$what" = run ]; then
  build build -DLIDARLOOP_BUILD_TESTS=OFF
  # Main job: the default dynamic scenario with the localizer in the loop, scored against ground
  # truth (exit 1 if it fails its thresholds).
  exec build/tools/lidarloop run scenarios/dynamic_campus.yaml --out build/out/dynamic_campus
fi

build build
ctest --test-dir build --output-on-failure -j "$jobs"
# The unit tests again under AddressSanitizer and UndefinedBehaviorSanitizer.
build build-sanitize -DLIDARLOOP_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-sanitize --output-on-failure -j "$jobs" -L unit
