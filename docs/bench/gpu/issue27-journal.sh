#!/bin/bash
# Issue 27 on the GPU machine, one device call (about 130 s), from the repository root:
#     . docs/bench/gpu/issue27-journal.sh        (carry: .device-bundle/distance-s7, made by
#                                                 docs/bench/gpu/issue27-bundle.sh build distance-s7)
# The change journal's cost on stage 2 (daemon/map/change_journal.h), measured apart: in one daemon,
# octomap-rt-distance-bench --journal-phases 2 maps scan_dat with 3 producers (vulkan mapping back end)
# twice before any distance query (journal unarmed), then, after the idle box and point queries armed it,
# twice more, and prints the armed/unarmed throughput ratio and stage 2's own time in the journal
# (ms a scan, share of the phases' time); then its usual phases (boxes and points beside producers,
# exploring), EDT on the H200. The whole run twice (fresh daemons), for the spread between runs.
# Every step is skipped, never cut, once its time is past. Results: $OUT/distance-s7.tar.gz.
. docs/bench/gpu/lib.sh "${ISSUE27_BUNDLE:-distance-s7}"
B=$N/bin/octomap-rt-distance-bench G=$N/data/octomap_share/scan_dat.graph
run() { local tag=$1; shift; log "$tag"
  timeout 60 "$B" --graph "$G" --phase-s 5 --journal-phases 2 --wait-s 20 --answer-timeout-s 10 \
    --csv "$O/$tag.csv" -r 0.1 --backend vulkan --warm-up-points 0 --distance-backend vulkan \
    --distance-threads 16 --reference-reps 1 --box-queries 20 --point-queries 40 "$@" > "$O/$tag.txt" 2>&1
  echo "rc=$? seconds=$((SECONDS - start))" >> "$O/$tag.txt"; }
left 25 && run journal1
left 85 && run journal2
