#!/bin/bash
# Issue 23 (helper mapstate): the big-map benchmark on the GPU machine, in one device call. A campus map of
# >= 20 M nodes (the campus preset, 10 % of its scans at 0.1 m), saved once; then fresh in-process daemons on it
# (octomap-rt-bigmap-bench run: memq://, the vulkan back end), 3 producers streaming campus scans for 45 s each:
#   readers off                      (the baseline: no snapshot, no autosave, no viewer map, no queries)
#   readers on, --read-replica off   (before: readers copy the map under the map lock)
#   readers on, --read-replica on    (after: readers read the replica; from session 3 on, 2026-12-02, the replica
#                                     applies the scans that wait together, on every core its helpers at the lowest
#                                     priority; queries read it while stage 2 holds the map)
#   unbatched (session 3 on)         the replica one scan per update on 4 threads at the server's priority (the
#                                     design of the first H200 run), for the same-call comparison
# "readers on" = a fresh snapshot pulled every second, autosave every 10 s, the OCTOMAP viewer map at 1 Hz,
# 100 point queries a second. Each run prints the octree stage's longest lock wait (the stall readers caused),
# scans' end-to-end p50/p99, queries' p50/p99, snapshot fetch times and RSS (docs/BENCHMARKS.md, issue 23).
#
# Here first (dev machine), from the repository root, with a build that has the targets:
#   cmake --build build -j2 --target octomap-rt octomap-rt-server octomap-rt-scenegen octomap-rt-bigmap-bench
#   docs/bench/gpu/make-bundle.sh build mapstate
#   cp build/tools/bigmap_bench/octomap-rt-bigmap-bench .device-bundle/mapstate/bin/ && strip .device-bundle/mapstate/bin/octomap-rt-bigmap-bench
#   ../shared/device/bundle-libs .device-bundle/mapstate .device-bundle/mapstate/bin/*
# There: run `bash docs/bench/gpu/issue23-bigmap.sh` with carry [".device-bundle/mapstate"]; the result comes
# back as mapstate.tar.gz (progress.txt, grow.txt, run-*.txt, machine.txt).
. docs/bench/gpu/lib.sh mapstate
B=$N/bin/octomap-rt-bigmap-bench
E=(-r 0.1 --backend vulkan --preset campus --scan-scale 0.1)
log grow
timeout 240 "$B" grow "${E[@]}" --point-scale 1 --target-nodes 20000000 --map "$T/big.ot" > "$O/grow.txt" 2>&1
echo "rc=$?" >> "$O/grow.txt"
R=(--map "$T/big.ot" --stream-point-scale 0.25 --producers 3 --rate 3 --duration 45)
# Each run at most 170 s and never past 575 s into the call (the result is packed at exit).
run() { local name=$1; shift; log "run-$name"; local t=$((575 - (SECONDS - start))); [ "$t" -gt 170 ] && t=170
  timeout "$t" "$B" run "${E[@]}" "${R[@]}" "$@" > "$O/run-$name.txt" 2>&1
  echo "rc=$?" >> "$O/run-$name.txt"; }
left 300 && run off-a --readers off --read-replica off
left 360 && run after-a --readers on --read-replica on
left 420 && run unbatched-a --readers on --read-replica on --replica-batch-voxels 0 --replica-nice 0 --replica-threads 4
left 470 && run off-b --readers off --read-replica off
left 520 && run after-b --readers on --read-replica on
grep -h '^csv' "$O"/run-*.txt > "$O/runs.csv" 2>/dev/null
exit 0
