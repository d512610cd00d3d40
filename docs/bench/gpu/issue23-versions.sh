#!/bin/bash
# Issue 23 (helper replica): whole-map readers on versions kept per region, on the H200, in one short device call
# (at most 150 s). Same map, producers and readers as issue23-bigmap.sh (a >= 20 M-node campus map; 3 producers
# streaming campus scans; "readers on" = a fresh snapshot pulled every second, autosave every 10 s, the OCTOMAP
# viewer map at 1 Hz, 100 point queries a second), 20 s of streaming a run, one binary:
#   off-a     readers off, no replica (the baseline)
#   after-a   readers on, the read replica with whole-map readers on its versions (octree/versions/map_version.h)
#   before-a  the same with session 5's versions (--replica-version-writes regions: every region the scans' keys
#             touched rewritten whole, on the replica's thread alone)
# Session 6: a version costs what changed: the replica's octree stage logs the leaves it changed, the builder marks
# their cells (a region's nodes 3 levels below its root) and writes a changed region from its old records, copying
# every subtree without a changed cell and writing only the changed cells from the tree
# (octree/versions/region_records.h), the changed regions written on the replica's helper threads (nice 19). Session 5 rewrote every region a scan's keys touched, whole: 12.8 of 30 s of
# the replica's thread, stage 2 waiting 9.1 s for room, e2e p99 1.9 s against 275 ms off.
# Look at: after-a's "versions for whole-map readers" (N made, X s in all, at most Y ms), "stage 2 waited ... for
# room", "lock wait max" (goal <= 2 ms), its e2e p99 against off-a's (goal within 10 %), queries' p99 (goal 5 ms).
# The bundle holds only the bench program (it runs the daemon in-process), stripped, and its libraries. Here
# (dev machine), from the repository root, with a build of this commit (BUNDLE: the bundle's name, replica-s6):
#   cmake --build build -j2 --target octomap-rt-bigmap-bench
#   rm -rf .device-bundle/replica-s6 && mkdir -p .device-bundle/replica-s6/bin
#   cp build/tools/bigmap_bench/octomap-rt-bigmap-bench .device-bundle/replica-s6/bin/ && strip .device-bundle/replica-s6/bin/*
#   ../shared/device/bundle-libs .device-bundle/replica-s6 .device-bundle/replica-s6/bin/*
# Tried here on lavapipe first: BACKEND=vulkan TARGET_NODES=300000 GROW_POINT_SCALE=0.2 STREAM_POINT_SCALE=0.01
# DURATION=10 OUT=/tmp/x bash docs/bench/gpu/issue23-versions.sh.
# There: `bash docs/bench/gpu/issue23-versions.sh`, carry [".device-bundle/replica-s6"]; the result comes back as
# replica-s6.tar.gz (progress.txt, grow.txt, run-*.txt, runs.csv, machine.txt).
. docs/bench/gpu/lib.sh ${BUNDLE:-replica-s6}
B=$N/bin/octomap-rt-bigmap-bench
E=(-r 0.1 --backend ${BACKEND:-vulkan} --preset campus --scan-scale 0.1)
log grow
timeout 30 "$B" grow "${E[@]}" --point-scale ${GROW_POINT_SCALE:-1} --target-nodes ${TARGET_NODES:-20000000} \
  --map "$T/big.ot" > "$O/grow.txt" 2>&1
echo "rc=$?" >> "$O/grow.txt"
R=(--map "$T/big.ot" --stream-point-scale ${STREAM_POINT_SCALE:-0.25} --producers 3 --rate 3 --duration ${DURATION:-20})
# run NAME CAP ARGS: at most CAP s and never past 145 s into the call (the result is packed at exit).
run() { local name=$1 cap=$2; shift 2; log "run-$name"; local t=$((145 - (SECONDS - start))); [ "$t" -gt "$cap" ] && t=$cap
  timeout "$t" "$B" run "${E[@]}" "${R[@]}" "$@" > "$O/run-$name.txt" 2>&1
  echo "rc=$?" >> "$O/run-$name.txt"; }
left 50 && run off-a 40 --readers off --read-replica off
left 90 && run after-a 55 --readers on --read-replica on
left 105 && run before-a 40 --readers on --read-replica on --replica-version-writes regions
grep -h '^csv' "$O"/run-*.txt > "$O/runs.csv" 2>/dev/null
exit 0
