#!/usr/bin/env bash
# Installs what is missing (Debian bookworm packages, as root) and builds octomap-rt into
# build/. Run by tools/run-demo and tools/run-tests; safe to run again.
#   tools/setup.sh demo               the packages and the programs tools/run-demo runs
#   tools/setup.sh [tests]            everything the tests use, and the whole tree (the default)
#   tools/setup.sh packages GROUP...  only install the packages of the groups below
# OCTOMAP_RT_BUILD_DIR (default build/) and OCTOMAP_RT_CMAKE_ARGS (extra configure flags) apply.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# Package groups, each with what needs it.
declare -A groups
# Configure and build: compilers, LCM (lcm-gen), OctoMap, Vulkan + lavapipe, shaders, the libraries.
groups[build]="cmake ninja-build g++ pkg-config liblcm-dev liblcm-bin liboctomap-dev libeigen3-dev
  libvulkan-dev mesa-vulkan-drivers glslang-tools libjemalloc-dev libzstd-dev libsodium-dev libgtest-dev libcli11-dev
  libpng-dev"
# tools/run-demo: its network namespace (ip) and the Python planner example (client/bindings/python).
groups[demo]="iproute2 python3 python3-numpy"
# The tests beyond the demo's: the Python client's snapshots (zstd), the Java example and types jar,
# libdynamicedt3d-dev for distance_test's DynamicEDTOctomap check, gnuplot for the bench's charts, bzip2 for the data sets' sources (scan.dat.bz2), octomap-tools for
# graph2tree (the peak-memory benchmark measures it beside octomap-rt build: issue 25).
groups[tests]="python3-zstandard liblcm-java default-jdk-headless bzip2 gnuplot-nox octomap-tools libdynamicedt3d-dev"
# The libFuzzer targets (tests/fuzz/, run by tools/run-tests).
groups[fuzz]="clang-14 libclang-rt-14-dev"
# The format check of every C++ file (tools/check-format, run by tools/run-tests).
groups[format]="clang-format-14"
# lcm-spy (tools/octomap-rt-spy: a JRE with AWT, jchart2d) and the screenshot tools (Xvfb, xdotool,
# ImageMagick's import: tools/spy-screenshot/).
groups[viewers]="liblcm-java libjchart2d-java default-jre xvfb xdotool imagemagick"

install_groups() {
  local missing=() p g
  for g in "$@"; do
    [ -n "${groups[$g]:-}" ] || { echo "octomap-rt setup: no package group '$g' (${!groups[*]})" >&2; exit 2; }
    for p in ${groups[$g]}; do
      dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "octomap-rt setup: installing ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    local sudo_cmd=""
    [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
    $sudo_cmd apt-get update -q
    $sudo_cmd apt-get install -y -q --no-install-recommends "${missing[@]}"
  fi
}

what=${1:-tests}
build_dir=${OCTOMAP_RT_BUILD_DIR:-$repo/build}
configure() {
  local launcher=()
  # ccache, where it is installed, makes rebuilds of unchanged files cheap (not installed here).
  command -v ccache > /dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  cmake -S "$repo" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" ${OCTOMAP_RT_CMAKE_ARGS:-}
}
case "$what" in
  packages)
    shift
    install_groups "$@"
    ;;
  demo)
    install_groups build demo
    configure
    cmake --build "$build_dir" --parallel "$(nproc)" --target octomap-rt octomap-rt-server octomap-rt-plan octomap_rt_python
    ;;
  tests)
    install_groups build demo tests
    configure
    cmake --build "$build_dir" --parallel "$(nproc)"
    ;;
  *)
    echo "usage: tools/setup.sh [demo|tests|packages GROUP...]" >&2
    exit 2
    ;;
esac
