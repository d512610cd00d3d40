#!/bin/bash
# Issue 27 (distance queries): makes .device-bundle/issue27 for docs/bench/gpu/issue27-distance.sh, here on
# the dev machine, from a build tree with the bench and the Vulkan EDT's exactness test built:
#     cmake --build build --target octomap-rt-distance-bench gpu_distance_test &&
#       docs/bench/gpu/issue27-bundle.sh build
# (octomap-rt-shard-bench, when built, comes too: issue 26's pinned shard runs, ISSUE26=1 in the call).
set -euo pipefail
build=${1:-build}
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)
B=$repo/.device-bundle/issue27
rm -rf "$B"; mkdir -p "$B/bin" "$B/data/octomap_share" "$B/data/3dtk_dat"
cp "$build/tools/distance-bench/octomap-rt-distance-bench" "$build/tests/gpu_distance_test" "$B/bin/"
[ -x "$build/tools/shard_bench/octomap-rt-shard-bench" ] && cp "$build/tools/shard_bench/octomap-rt-shard-bench" "$B/bin/"
strip "$B"/bin/*
cp "$repo"/../shared/data/octomap_share/{scan_dat.graph,geb079.bt} "$B/data/octomap_share/"
cp "$repo/../shared/data/3dtk_dat/3dtk_3scans.graph" "$B/data/3dtk_dat/"
"$repo/../shared/device/bundle-libs" "$B" "$B"/bin/*
du -sh "$B"
