#!/bin/bash
# Issue 23 (helper replica, session 5): whole-map readers on versions kept per region, on the H200, in one short
# device call (at most 230 s). Same map, producers and readers as issue23-bigmap.sh (a >= 20 M-node campus map;
# 3 producers streaming campus scans; "readers on" = a fresh snapshot pulled every second, autosave every 10 s,
# the OCTOMAP viewer map at 1 Hz, 100 point queries a second), 30 s of streaming a run:
#   off-a    readers off, no replica (the baseline)
#   after-a  readers on, the read replica with whole-map readers on its versions (octree/versions/map_version.h): no
#            reader copies or locks the tree; the replica's thread writes again only the regions scans touched
# What changed since issue23-replica-lock.sh: snapshots, saves and the viewer map read an immutable version of the
# replica (daemon/map/map_replica.h read_version) instead of copying its tree under its lock. Look at: after-a's
# "lock wait max" (the stall readers caused; goal <= 2 ms), its e2e p99 against off-a's (goal within 10 %),
# "read replica's lock held by" (no copy holds it now), "versions for whole-map readers" (what making them
# cost the replica's thread) and the queries' p99 (goal 5 ms).
# The bundle holds only the bench program (it runs the daemon in-process), stripped, and its libraries. Here
# (dev machine), from the repository root, with a build of this commit:
#   cmake --build build -j2 --target octomap-rt-bigmap-bench
#   rm -rf .device-bundle/replica && mkdir -p .device-bundle/replica/bin
#   cp build/tools/bigmap_bench/octomap-rt-bigmap-bench .device-bundle/replica/bin/ && strip .device-bundle/replica/bin/*
#   ../shared/device/bundle-libs .device-bundle/replica .device-bundle/replica/bin/*
# Tried here on lavapipe first: BACKEND=vulkan TARGET_NODES=300000 GROW_POINT_SCALE=0.2 STREAM_POINT_SCALE=0.01
# DURATION=10 OUT=/tmp/x bash docs/bench/gpu/issue23-versions.sh.
# There: `bash docs/bench/gpu/issue23-versions.sh`, carry [".device-bundle/replica"]; the result comes back as
# replica.tar.gz (progress.txt, grow.txt, run-*.txt, runs.csv, machine.txt).
. docs/bench/gpu/lib.sh replica
B=$N/bin/octomap-rt-bigmap-bench
E=(-r 0.1 --backend ${BACKEND:-vulkan} --preset campus --scan-scale 0.1)
log grow
timeout 60 "$B" grow "${E[@]}" --point-scale ${GROW_POINT_SCALE:-1} --target-nodes ${TARGET_NODES:-20000000} \
  --map "$T/big.ot" > "$O/grow.txt" 2>&1
echo "rc=$?" >> "$O/grow.txt"
R=(--map "$T/big.ot" --stream-point-scale ${STREAM_POINT_SCALE:-0.25} --producers 3 --rate 3 --duration ${DURATION:-30})
# Each run at most 100 s and never past 225 s into the call (the result is packed at exit).
run() { local name=$1; shift; log "run-$name"; local t=$((225 - (SECONDS - start))); [ "$t" -gt 100 ] && t=100
  timeout "$t" "$B" run "${E[@]}" "${R[@]}" "$@" > "$O/run-$name.txt" 2>&1
  echo "rc=$?" >> "$O/run-$name.txt"; }
left 100 && run off-a --readers off --read-replica off
left 160 && run after-a --readers on --read-replica on
grep -h '^csv' "$O"/run-*.txt > "$O/runs.csv" 2>/dev/null
exit 0
