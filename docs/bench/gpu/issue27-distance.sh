#!/bin/bash
# Issue 27 on the GPU machine, one device call (about 5 minutes), from the repository root:
#     . docs/bench/gpu/issue27-distance.sh        (carry: .device-bundle/issue27, made by issue27-bundle.sh)
# First the Vulkan EDT's exactness on the device (gpu_distance_test: GPU = CPU bit for bit on random and
# real-map grids). Then octomap-rt-distance-bench: the 20 x 20 x 3 m box at 0.1 m and 1000-point queries,
# idle and while 3 producers stream scan_dat's scans as fast as the daemon maps them (vulkan mapping back
# end), mapping throughput with 10 box queries/s against none, and the same box in-process (octomap-rt's
# read + EDT on 16 CPU threads and on the device, and OctoMap's DynamicEDTOctomap): the daemon's EDT on the
# H200 (--distance-backend vulkan), then on 16 CPU threads. Last, issue 26's shard set with a core
# per daemon (docs/bench/gpu/issue26-pinned.sh). Every step is skipped, never cut, once its time
# is past (the call stays under 8 minutes). Results: $OUT/issue27.tar.gz.
. docs/bench/gpu/lib.sh issue27
B=$N/bin/octomap-rt-distance-bench G=$N/data/octomap_share/scan_dat.graph
log exactness
OCTOMAP_RT_DATA=$N/data timeout 120 "$N/bin/gpu_distance_test" > "$O/gpu_distance_test.txt" 2>&1
echo "rc=$?" >> "$O/gpu_distance_test.txt"
run() { local tag=$1; shift; log "$tag"
  timeout 150 "$B" --graph "$G" --phase-s 8 --wait-s 60 --answer-timeout-s 20 --csv "$O/$tag.csv" -r 0.1 \
    --backend vulkan --warm-up-points 0 "$@" > "$O/$tag.txt" 2>&1; echo "rc=$?" >> "$O/$tag.txt"; }
left 150 && run vulkan --distance-backend vulkan --distance-threads 16 --reference-vulkan
left 330 && run cpu16 --distance-backend cpu --distance-threads 16
left 400 && [ -x "$N/bin/octomap-rt-shard-bench" ] && . docs/bench/gpu/issue26-pinned.sh
