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
  mkdir -p build/out
  # Main job: one HDL-32E scan on the campus, driving at 10 m/s behind a truck, past a bus parked on
  # the other side of the road, while a pedestrian walks onto the sidewalk.
  build/tools/lidarloop scan --world campus --pose 240,-2.25,0 --speed 10 \
    --actor bus,252,3.0,180 --actor truck,262,-2.25,0,8 --actor pedestrian,236,-6.5,90,1.4 \
    --out build/out/scan.ply --png build/out/scan.png
  exit 0
fi

build build
ctest --test-dir build --output-on-failure -j "$jobs"
# The unit tests again under AddressSanitizer and UndefinedBehaviorSanitizer.
build build-sanitize -DLIDARLOOP_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-sanitize --output-on-failure -j "$jobs" -L unit
