#!/bin/bash
# Issue 27 on the GPU machine, session 9 (about 110 s), from the repository root, in its own shell:
#     mkdir -p $OUT/distance && OUT=$OUT/distance bash docs/bench/gpu/issue27-slabs.sh
# (carry: .device-bundle/distance-s9, made by docs/bench/gpu/issue27-bundle.sh build distance-s9).
# octomap-rt-distance-bench with session 6's 'lists' options (EDT and mapping on the H200): a box reply made
# by z-slabs (daemon/queries/box_frames.h: slabs of 65536 cells cut, clamped and compressed apart on the 16
# distance threads, an unchanged slab's frame kept from the last reply; the default) against the whole box as
# one zstd frame on one thread (--distance-slab-cells 0: the reply as before), alternating in fresh daemons,
# two runs each: box p50 / p99 idle, beside 3 producers, exploring; and each run's in-process "by z-slabs"
# line (both ways on the same field, same process). Every run is skipped, never cut, once its start time is
# past. Results: $OUT/distance-s9.tar.gz.
. docs/bench/gpu/lib.sh "${ISSUE27_BUNDLE:-distance-s9}"
B=$N/bin/octomap-rt-distance-bench G=$N/data/octomap_share/scan_dat.graph
run() { local tag=$1; shift; log "$tag"
  timeout 28 "$B" --graph "$G" --phase-s 4 --wait-s 10 --answer-timeout-s 10 --csv "$O/$tag.csv" -r 0.1 \
    --backend vulkan --warm-up-points 0 --distance-backend vulkan --distance-threads 16 --reference-reps 3 \
    --box-queries 20 --point-queries 20 "$@" > "$O/$tag.txt" 2>&1
  echo "rc=$? seconds=$((SECONDS - start))" >> "$O/$tag.txt"; }
left 10 && run slabs1
left 35 && run whole1 --distance-slab-cells 0
left 58 && run slabs2
left 80 && run whole2 --distance-slab-cells 0
