#!/bin/bash
# Issue 26: makes .device-bundle/NAME (default shards-s7) for docs/bench/gpu/issue26-corun.sh and issue26-balance.sh,
# here on the dev machine, from a build tree with the shard benches, the server and the CLI built:
#     cmake --build build --target octomap-rt-shard-bench octomap-rt-shard-query-bench octomap-rt-server octomap-rt &&
#         docs/bench/gpu/issue26-balance-bundle.sh build [NAME]
# The graphs go xz-packed (the script unpacks them there) and the GL libraries NVIDIA's Vulkan driver needs stay
# out (every step runs on the CPU), so that the bundle stays under 15 MiB.
set -euo pipefail
build=${1:-build}
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../../.." && pwd)
B=$repo/.device-bundle/${2:-shards-s7}
rm -rf "$B"; mkdir -p "$B/bin" "$B/data/octomap_share" "$B/data/3dtk_dat"
cp "$build/tools/shard_bench/octomap-rt-shard-bench" "$build/tools/shard_bench/octomap-rt-shard-query-bench" \
  "$build/server/octomap-rt-server" "$build/client/octomap-rt" "$(command -v ip)" "$B/bin/"
strip "$B"/bin/*
xz -9e -c "$repo/../shared/data/octomap_share/scan_dat.graph" > "$B/data/octomap_share/scan_dat.graph.xz"
xz -9e -c "$repo/../shared/data/3dtk_dat/3dtk_3scans.graph" > "$B/data/3dtk_dat/3dtk_3scans.graph.xz"
"$repo/../shared/device/bundle-libs" "$B" "$B"/bin/*
rm -f "$B"/lib/libGLdispatch.so.0 "$B"/lib/libGLX.so.0 "$B"/lib/libEGL.so.1 "$B"/lib/libOpenGL.so.0
du -sh "$B"
