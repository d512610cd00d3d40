#!/bin/bash
# Issue 27 (distance queries): makes .device-bundle/issue27 for docs/bench/gpu/issue27-distance.sh, here on
# the dev machine, from a build tree with octomap-rt-distance-bench built:
#     cmake --build build --target octomap-rt-distance-bench && docs/bench/gpu/issue27-bundle.sh build
set -euo pipefail
build=${1:-build}
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)
B=$repo/.device-bundle/issue27
rm -rf "$B"; mkdir -p "$B/bin" "$B/data"
cp "$build/tools/distance-bench/octomap-rt-distance-bench" "$B/bin/"
strip "$B/bin/octomap-rt-distance-bench"
cp "$repo/../shared/data/octomap_share/scan_dat.graph" "$B/data/"
"$repo/../shared/device/bundle-libs" "$B" "$B"/bin/*
du -sh "$B"
