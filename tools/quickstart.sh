#!/usr/bin/env bash
# The two quick-start commands of the README.
#   tools/quickstart.sh run    install what is missing, build, run the main job
#   tools/quickstart.sh test   install what is missing, build, run every test (also under ASan + UBSan)
set -euo pipefail
cd "$(dirname "$0")/.."

what=${1:-}
case "$what" in run|test) ;; *) echo "usage: tools/quickstart.sh run|test" >&2; exit 2 ;; esac

# Each phase's wall time (the main job's own line says how long it ran), so a slow CI run shows where its
# minutes went.
phase_start=$SECONDS
took() {  # took WHAT: print how long the phase just ended took
  echo "quickstart: $1 took $((SECONDS - phase_start)) s (${SECONDS} s in all)"
  phase_start=$SECONDS
}
if [ "$what" = run ]; then tools/install_deps.sh run; else tools/install_deps.sh; fi
took install
jobs=$(nproc)
configure() {  # configure DIR [cmake options...]: every option is given each time, so nothing an earlier
               # configuration of DIR left in its cache (say, the tests switched off by `run`) carries over
  local dir=$1; shift
  cmake -S . -B "$dir" -G Ninja "$@" >/dev/null
}
build() {  # build DIR [cmake options...]: configure, then build everything
  configure "$@"
  cmake --build "$1" -j "$jobs"
}
# Fails when a label has no tests: a configuration that silently left a group out must not pass.
expect_tests() {  # expect_tests DIR LABEL...
  local dir=$1; shift
  for label in "$@"; do
    local count
    count=$(ctest --test-dir "$dir" -N -L "^$label\$" | sed -n 's/^Total Tests: //p')
    if [ "${count:-0}" -eq 0 ]; then
      echo "quickstart: no tests labelled '$label' in $dir" >&2
      exit 1
    fi
    echo "quickstart: $count tests labelled '$label'"
  done
}

if [ "$what" = run ]; then
  # The gicp method where Open3D is installed (after `test`, or by hand): the main job does not need it.
  gicp=OFF
  if dpkg-query -W -f='${Status}' libopen3d-dev 2>/dev/null | grep -q "install ok installed"; then gicp=ON; fi
  build build -DCMAKE_BUILD_TYPE=Release -DLIDARLOOP_BUILD_TESTS=OFF -DLIDARLOOP_BUILD_BENCHMARKS=OFF \
    -DLIDARLOOP_GICP=$gicp -DLIDARLOOP_SANITIZE=OFF
  took build
  # Main job: the default dynamic scenario with the localizer in the loop, scored against ground
  # truth (exit 1 if it fails its thresholds).
  exec build/tools/lidarloop run scenarios/dynamic_campus.yaml --out build/out/dynamic_campus
fi

# The optimized build runs the command-line, scenario, map, log and sweep tests, and the few unit tests
# too slow to run instrumented (LIDARLOOP_UNIT_TESTS=slow: tests/CMakeLists.txt lists them and why).
build build -DCMAKE_BUILD_TYPE=Release -DLIDARLOOP_BUILD_TESTS=ON -DLIDARLOOP_BUILD_BENCHMARKS=ON -DLIDARLOOP_GICP=ON \
  -DLIDARLOOP_SANITIZE=OFF -DLIDARLOOP_UNIT_TESTS=slow
took "optimized build"
expect_tests build unit cli scenario map node sweep external
ctest --test-dir build --output-on-failure --no-tests=error -j "$jobs"
took "optimized tests"
# Every other unit test under AddressSanitizer and UndefinedBehaviorSanitizer, and the libFuzzer targets
# (fuzz/) in the same instrumented build, by clang: only what they run is built, at -O1 with line tables
# only (-g1: file and line in the sanitizers' stack traces), to keep the instrumented build, which CI
# runs on two cores, short. A folder configured by another compiler is started afresh.
if [ -f build-sanitize/CMakeCache.txt ] && ! grep -q '^CMAKE_CXX_COMPILER:[A-Z]*=.*clang++' build-sanitize/CMakeCache.txt; then
  rm -rf build-sanitize
fi
configure build-sanitize -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" \
  -DLIDARLOOP_BUILD_TESTS=ON -DLIDARLOOP_SANITIZE=ON -DLIDARLOOP_FUZZ=ON -DLIDARLOOP_BUILD_BENCHMARKS=OFF -DLIDARLOOP_GICP=ON \
  -DLIDARLOOP_UNITY_BUILD=OFF -DLIDARLOOP_UNIT_TESTS=fast
cmake --build build-sanitize -j "$jobs" --target unit_tests fuzz_targets
took "instrumented build"
expect_tests build-sanitize unit fuzz link
# With them, every reader of outside files fuzzed for a bounded time (LIDARLOOP_FUZZ_SECONDS each): a
# crash, a hang, a sanitizer report or an exception other than the reader's InputError fails; and the
# check that the localizer's and the logs' tests link no simulator code. One ctest for all, so that none
# waits with a core idle for another's last test.
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
  ctest --test-dir build-sanitize --output-on-failure --no-tests=error -j "$jobs" -L '^(unit|fuzz|link)$'
took "instrumented tests"
