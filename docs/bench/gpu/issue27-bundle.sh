#!/bin/bash
# Issue 27 (distance queries): makes .device-bundle/NAME (default distance-s6) for
# docs/bench/gpu/issue27-distance.sh, here on the dev machine, from a build tree with the bench built:
#     cmake --build build --target octomap-rt-distance-bench && docs/bench/gpu/issue27-bundle.sh build [NAME]
# (about 9 MiB). With EXACTNESS=1 the Vulkan EDT's exactness test and its three maps come too (about
# 18 MiB; build gpu_distance_test first).
set -euo pipefail
build=${1:-build}
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)
B=$repo/.device-bundle/${2:-distance-s6}
rm -rf "$B"; mkdir -p "$B/bin" "$B/data/octomap_share"
cp "$build/tools/distance-bench/octomap-rt-distance-bench" "$B/bin/"
cp "$repo/../shared/data/octomap_share/scan_dat.graph" "$B/data/octomap_share/"
if [ "${EXACTNESS:-0}" = 1 ]; then
  mkdir -p "$B/data/3dtk_dat"
  cp "$build/tests/gpu_distance_test" "$B/bin/"
  cp "$repo/../shared/data/octomap_share/geb079.bt" "$B/data/octomap_share/"
  cp "$repo/../shared/data/3dtk_dat/3dtk_3scans.graph" "$B/data/3dtk_dat/"
fi
strip "$B"/bin/*
"$repo/../shared/device/bundle-libs" "$B" "$B"/bin/*
du -sh "$B"
