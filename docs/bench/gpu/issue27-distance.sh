#!/bin/bash
# Issue 27 on the GPU machine, one device call (about 3 minutes), from the repository root:
#     . docs/bench/gpu/issue27-distance.sh        (carry: .device-bundle/issue27, made by issue27-bundle.sh)
# First the Vulkan EDT's exactness on the device (gpu_distance_test: GPU = CPU bit for bit on random and
# real-map grids). Then octomap-rt-distance-bench: the 20 x 20 x 3 m box at 0.1 m and 1000-point queries,
# idle and while 3 producers stream scan_dat's scans as fast as the daemon maps them (vulkan mapping back
# end), mapping throughput with 10 box queries/s against none, the box reply stage by stage in-process,
# and the same box against OctoMap's DynamicEDTOctomap. Three daemons, the EDT on the H200
# (--distance-backend vulkan) in each, so their ratios come from the same call:
#   whole   every field computed whole (--distance-field-cache false: the path before the cache);
#   cached  the field cache (the default): a box asked again transforms only where its grid changed;
#   nopace  the cache and no pause between a reply's chunks (--query-chunk-interval-ms 0: memq://).
# (Issue 26's pinned shard set, sourced last in session 4, is left out: `ISSUE26=1` adds it after these.)
# Every step is skipped, never cut, once its time is past. Results: $OUT/issue27.tar.gz.
. docs/bench/gpu/lib.sh issue27
B=$N/bin/octomap-rt-distance-bench G=$N/data/octomap_share/scan_dat.graph
log exactness
OCTOMAP_RT_DATA=$N/data timeout 120 "$N/bin/gpu_distance_test" > "$O/gpu_distance_test.txt" 2>&1
echo "rc=$?" >> "$O/gpu_distance_test.txt"
run() { local tag=$1; shift; log "$tag"
  timeout 100 "$B" --graph "$G" --phase-s 6 --wait-s 30 --answer-timeout-s 20 --csv "$O/$tag.csv" -r 0.1 \
    --backend vulkan --warm-up-points 0 --distance-backend vulkan --distance-threads 16 "$@" > "$O/$tag.txt" 2>&1
  echo "rc=$?" >> "$O/$tag.txt"; }
left 60 && run whole --distance-field-cache false --reference-vulkan
left 160 && run cached
left 260 && run nopace --query-chunk-interval-ms 0
[ "${ISSUE26:-0}" = 1 ] && left 400 && [ -x "$N/bin/octomap-rt-shard-bench" ] && . docs/bench/gpu/issue26-pinned.sh
