#!/usr/bin/env bash
# Installs the Debian packages lidarloop needs, skipping those already present.
# Idempotent; works as root or through sudo. Used by both quick-start commands.
#   tools/install_deps.sh        everything: the program, the gicp method, the tests, the checks
#   tools/install_deps.sh run    only what the program and its main job need (`quickstart.sh run`):
#                                291 packages instead of about 800 on Debian 12 (no Open3D, clang,
#                                clang-format, Node.js)
set -euo pipefail
case "${1:-all}" in run|all) ;; *) echo "usage: tools/install_deps.sh [run|all]" >&2; exit 2 ;; esac

packages=(
  cmake g++ ninja-build ccache pkg-config
  libembree-dev libeigen3-dev libgeographiclib-dev libnanoflann-dev libyaml-cpp-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev
  libpolyclipping-dev nlohmann-json3-dev libzstd-dev
  libpugixml-dev
)
if [ "${1:-all}" != run ]; then
  packages+=(
    libopen3d-dev  # the gicp method (localizer/gicp_open3d.cpp)
    clang-format
    clang libclang-rt-14-dev  # the sanitizer build and its libFuzzer targets (fuzz/)
    libgtest-dev libgmock-dev libbenchmark-dev
  )
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# The MCAP cross-check test (label `node`) runs Node.js; a node already on PATH (e.g. from
# NodeSource) is kept, Debian's nodejs and npm are installed only when there is none.
[ "${1:-all}" = run ] || command -v node >/dev/null 2>&1 || missing+=(nodejs npm)
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -eq 0 ]; then sudo_cmd=(); else sudo_cmd=(sudo); fi
echo "install_deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
