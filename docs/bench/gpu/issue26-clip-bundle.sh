#!/bin/bash
# Issue 26 (the ray clip): makes .device-bundle/issue26 for docs/bench/gpu/issue26-clipped.sh, here on the
# dev machine, from a build tree with the shard bench built:
#     cmake --build build --target octomap-rt-shard-bench && docs/bench/gpu/issue26-clip-bundle.sh build
set -euo pipefail
build=${1:-build}
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)
B=$repo/.device-bundle/issue26
rm -rf "$B"; mkdir -p "$B/bin" "$B/data/octomap_share" "$B/data/3dtk_dat"
cp "$build/tools/shard_bench/octomap-rt-shard-bench" "$B/bin/"
strip "$B"/bin/*
cp "$repo/../shared/data/octomap_share/scan_dat.graph" "$B/data/octomap_share/"
cp "$repo/../shared/data/3dtk_dat/3dtk_3scans.graph" "$B/data/3dtk_dat/"
"$repo/../shared/device/bundle-libs" "$B" "$B"/bin/*
du -sh "$B"
