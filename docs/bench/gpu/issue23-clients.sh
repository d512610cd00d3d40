#!/bin/bash
# Issue 23 (helper replica), session 9: the big-map bench with several query clients, on the H200, in one step of
# at most 120 s. Same map, producers and readers as issue23-versions.sh (a >= 20 M-node campus map; 3 producers
# streaming campus scans at 3 Hz; "readers on" = a fresh snapshot pulled every second, autosave every 10 s, the
# OCTOMAP viewer map at 1 Hz, 100 point queries a second), 15 s of streaming a run, one binary, fresh server each:
#   off       readers off, no replica (the baseline of the same call)
#   on-1      readers on, read replica on, the 100 queries/s from one client (session 6's shape)
#   on-3      the same with the 100 queries/s shared by 3 clients (own client ids): since 91fca85 a turn on the
#             replica takes the queries of every client answered from its state or older, so one client that
#             read the map of record no longer keeps the replica out of the other clients' turns
# Look at, per run: "scans applied ... in S s" (mapping throughput: on-N against off), "lock wait max" (stage 2's
# worst stall; goal <= 2 ms), "stage 2 waited ... for room", e2e p99 (goal within 10 % of off), queries' p99
# (goal 5 ms) and "answered not OK". runs.csv: one csv line a run (columns in bigmap_bench.cpp).
# Bundle (dev machine, repository root, a build of this commit):
#   cmake --build build -j2 --target octomap-rt-bigmap-bench
#   rm -rf .device-bundle/replica-s9 && mkdir -p .device-bundle/replica-s9/bin
#   cp build/tools/bigmap_bench/octomap-rt-bigmap-bench .device-bundle/replica-s9/bin/ && strip .device-bundle/replica-s9/bin/*
#   ../shared/device/bundle-libs .device-bundle/replica-s9 .device-bundle/replica-s9/bin/*
# There: OUT=$OUT/replica bash docs/bench/gpu/issue23-clients.sh, carry [".device-bundle/replica-s9"];
# the result comes back as replica-s9.tar.gz (progress.txt, grow.txt, run-*.txt, runs.csv, machine.txt).
. docs/bench/gpu/lib.sh ${BUNDLE:-replica-s9}
B=$N/bin/octomap-rt-bigmap-bench
E=(-r 0.1 --backend ${BACKEND:-vulkan} --preset campus --scan-scale 0.1)
log grow
timeout 25 "$B" grow "${E[@]}" --point-scale ${GROW_POINT_SCALE:-1} --target-nodes ${TARGET_NODES:-20000000} \
  --map "$T/big.ot" > "$O/grow.txt" 2>&1
echo "rc=$?" >> "$O/grow.txt"
R=(--map "$T/big.ot" --stream-point-scale ${STREAM_POINT_SCALE:-0.25} --producers 3 --rate 3 --duration ${DURATION:-15})
# run NAME CAP ARGS: at most CAP s and never past 112 s into the call (the result is packed at exit).
run() { local name=$1 cap=$2; shift 2; log "run-$name"; local t=$((112 - (SECONDS - start))); [ "$t" -gt "$cap" ] && t=$cap
  timeout "$t" "$B" run "${E[@]}" "${R[@]}" "$@" > "$O/run-$name.txt" 2>&1
  echo "rc=$?" >> "$O/run-$name.txt"; }
left 40 && run off 30 --readers off --read-replica off
left 70 && run on-3 34 --readers on --read-replica on --query-clients 3
left 85 && run on-1 30 --readers on --read-replica on --query-clients 1
grep -h '^csv' "$O"/run-*.txt > "$O/runs.csv" 2>/dev/null
exit 0
