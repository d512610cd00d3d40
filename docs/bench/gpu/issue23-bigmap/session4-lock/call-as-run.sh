#!/bin/bash
# Issue 23: does the read replica keep up on the H200 once its writer gets in between readers? One device
# call of at most 480 s, after issue23-bigmap.sh (same map, streaming and readers; docs/BENCHMARKS.md "Readers
# and the read replica"). What changed since that script's runs: the replica's lock prefers its writer
# (daemon/map/map_mutex.h) and stage 2 waits for the replica's room before it takes the map lock. Runs:
#   off-a      readers off, no replica (the baseline)
#   after-a    readers on, the replica with the server's defaults
#   after-big  the same with a 1 GiB pending bound and 32 M-voxel batches (what the defaults cost)
#   after-b    after-a again if the call has time left
# Here first: build octomap-rt octomap-rt-server octomap-rt-scenegen octomap-rt-bigmap-bench and make the bundle
# as issue23-bigmap.sh says (docs/bench/gpu/make-bundle.sh build mapstate, then the bench binary and
# bundle-libs); there: `bash docs/bench/gpu/issue23-replica-lock.sh`, carry [".device-bundle/mapstate"];
# the result comes back as mapstate.tar.gz.
. docs/bench/gpu/lib.sh mapstate
B=$N/bin/octomap-rt-bigmap-bench
E=(-r 0.1 --backend vulkan --preset campus --scan-scale 0.1)
log grow
timeout 60 "$B" grow "${E[@]}" --point-scale 1 --target-nodes 20000000 --map "$T/big.ot" > "$O/grow.txt" 2>&1
echo "rc=$?" >> "$O/grow.txt"
R=(--map "$T/big.ot" --stream-point-scale 0.25 --producers 3 --rate 3 --duration 45)
# Each run at most 140 s and never past 465 s into the call (the result is packed at exit).
run() { local name=$1; shift; log "run-$name"; local t=$((465 - (SECONDS - start))); [ "$t" -gt 140 ] && t=140
  timeout "$t" "$B" run "${E[@]}" "${R[@]}" "$@" > "$O/run-$name.txt" 2>&1
  echo "rc=$?" >> "$O/run-$name.txt"; }
left 300 && run off-a --readers off --read-replica off
left 340 && run after-a --readers on --read-replica on
left 380 && run after-big --readers on --read-replica on --replica-pending-bytes 1073741824 --replica-batch-voxels 33554432
left 400 && run after-b --readers on --read-replica on
grep -h '^csv' "$O"/run-*.txt > "$O/runs.csv" 2>/dev/null
exit 0
