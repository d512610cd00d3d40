#!/usr/bin/env bash
# Installs what is missing (Debian bookworm packages, as root) and builds octomap-rt into
# build/. Sourced by tools/run-demo and tools/run-tests; safe to run again.
set -euo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

packages=(cmake ninja-build g++ pkg-config
  liblcm-dev liblcm-bin liblcm-java default-jdk-headless libjchart2d-java
  liboctomap-dev libeigen3-dev libvulkan-dev mesa-vulkan-drivers glslang-tools
  libdynamicedt3d-dev  # OctoMap's DynamicEDTOctomap: the distance tests compare with it (tests/distance)
  libjemalloc-dev libzstd-dev libgtest-dev libcli11-dev libpng-dev iproute2 bzip2 gnuplot-nox
  python3 python3-numpy python3-zstandard  # the Python client and its tests (client/bindings/python, tests/python)
  default-jre xvfb xdotool   # lcm-spy needs a JRE with AWT (not headless); Xvfb+xdotool: docs/lcm-spy.png
  clang-14 libclang-rt-14-dev)  # libFuzzer targets (tests/fuzz/, run by tools/run-tests)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "octomap-rt setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -q
  $sudo_cmd apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

build_dir=${OCTOMAP_RT_BUILD_DIR:-$repo/build}
cmake -S "$repo" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo ${OCTOMAP_RT_CMAKE_ARGS:-}
cmake --build "$build_dir" --parallel "$(nproc)"
