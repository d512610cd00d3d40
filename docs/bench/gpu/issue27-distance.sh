#!/bin/bash
# Issue 27 on the GPU machine, one device call (about 150 s), from the repository root:
#     . docs/bench/gpu/issue27-distance.sh        (carry: .device-bundle/distance-s6, made by issue27-bundle.sh)
# First, when the bundle has it (EXACTNESS=1 in issue27-bundle.sh), the Vulkan EDT's exactness on the
# device (gpu_distance_test: GPU = CPU bit for bit on random and real-map grids; unchanged since session 5,
# where it passed 2/2 on the H200). Then octomap-rt-distance-bench: the 20 x 20 x 3 m box at 0.1 m and 1000-point queries,
# idle and while 3 producers stream scan_dat's scans as fast as the daemon maps them (vulkan mapping back
# end), mapping throughput with 10 box queries/s against none, a robot exploring (the producers' scans
# shifted into new space, boxes at 10/s), the field cache's counters after each phase (from the change
# lists or box reads; unchanged, partial, whole; replies' bytes kept), the box reply stage by stage
# in-process. Daemons, the EDT on the H200 (--distance-backend vulkan) in each, so their ratios come from
# the same call:
#   lists     the field cache kept from the scans' change lists (the default since session 6);
#   reread    the field cache, its box read from the map again for every query (--distance-change-lists
#             false: session 5's path);
#   nopace    lists and no pause between a reply's chunks (--query-chunk-interval-ms 0: memq://);
#   whole     every field computed whole (--distance-field-cache false), only when time is left.
# Every step is skipped, never cut, once its time is past. Results: $OUT/distance-s6.tar.gz.
. docs/bench/gpu/lib.sh "${ISSUE27_BUNDLE:-distance-s6}"
B=$N/bin/octomap-rt-distance-bench G=$N/data/octomap_share/scan_dat.graph
if [ -x "$N/bin/gpu_distance_test" ]; then log exactness
  OCTOMAP_RT_DATA=$N/data timeout 20 "$N/bin/gpu_distance_test" > "$O/gpu_distance_test.txt" 2>&1
  echo "rc=$?" >> "$O/gpu_distance_test.txt"; fi
run() { local tag=$1; shift; log "$tag"
  timeout 42 "$B" --graph "$G" --phase-s 5 --wait-s 20 --answer-timeout-s 10 --csv "$O/$tag.csv" -r 0.1 \
    --backend vulkan --warm-up-points 0 --distance-backend vulkan --distance-threads 16 --reference-reps 1 \
    --box-queries 20 --point-queries 40 "$@" > "$O/$tag.txt" 2>&1
  echo "rc=$?" >> "$O/$tag.txt"; }
left 25 && run lists
left 68 && run reread --distance-change-lists false
left 108 && run nopace --query-chunk-interval-ms 0
left 100 && run whole --distance-field-cache false
