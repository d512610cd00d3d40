#!/bin/bash
# Issue 27 on the GPU machine, one device call (about 2 minutes), from the repository root:
#     . docs/bench/gpu/issue27-distance.sh        (carry: .device-bundle/issue27, made by issue27-bundle.sh)
# The 20 x 20 x 3 m box at 0.1 m and 1000-point queries, idle and while 3 producers stream fr079's scans as fast
# as the daemon maps them (vulkan mapping back end), and mapping throughput with 10 box queries/s against none:
# the EDT on the H200 (--distance-backend vulkan) and on 16 CPU threads. Results: $OUT/issue27.tar.gz.
. docs/bench/gpu/lib.sh issue27
B=$N/bin/octomap-rt-distance-bench G=$N/data/scan_dat.graph
run() { local tag=$1; shift; log "$tag"
  timeout 100 "$B" --graph "$G" --phase-s 8 --csv "$O/$tag.csv" -r 0.1 --backend vulkan --warm-up-points 0 "$@" \
    > "$O/$tag.txt" 2>&1; echo "rc=$?" >> "$O/$tag.txt"; }
run vulkan --distance-backend vulkan
left 200 && run cpu16 --distance-backend cpu --distance-threads 16
left 320 && run vulkan-again --distance-backend vulkan
