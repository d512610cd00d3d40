#!/bin/bash
# Issue 23 (helper replica): the big-map bench with several query clients, on the H200, in one step of at most
# 290 s (sessions 9-11). Same producers and readers as issue23-versions.sh (3 producers streaming campus scans at
# 3 Hz; "readers on" = a fresh snapshot pulled every second, autosave every 10 s, the OCTOMAP viewer map at 1 Hz,
# 100 point queries a second), 15 s of streaming a run, one binary, fresh server each, on a campus map of
# TARGET_NODES (default 9 M since session 11: session 9's 25.7 M-node map took each run's 30 s cut to load and
# serve, so that call brought no figure):
#   off       readers off, no replica (the baseline of the same call)
#   on-3      readers on, read replica on, the 100 queries/s shared by 3 clients (own client ids): since 91fca85 a
#             turn on the replica takes the queries of every client answered from its state or older, and since
#             session 11 a turn that finds nothing free for the clients queued asks again with those queued then
#   on-1      the same with the 100 queries/s from one client (session 6's shape)
#   on-3-b5   on-3 with --replica-batch-ms 5 (the replica's catch-up cut into updates of about 5 ms), if time is left
# Each run waits at most DRAIN s (default 30) after streaming for the scans still queued (the rest count as not
# applied: "scans applied N of M"), so that it prints its figures within its cap; its stderr says how far it got.
# Look at, per run: "scans applied ... in S s" (mapping throughput: on-N against off), "lock wait max" (stage 2's
# worst stall; goal <= 2 ms), "stage 2 waited ... for room", e2e p99 (goal within 10 % of off), queries' p99
# (goal 5 ms) and "answered not OK". runs.csv: one csv line a run (columns in bigmap_bench.cpp).
# Bundle (dev machine, repository root, a build of this commit; the dev preset is RelWithDebInfo):
#   cmake --build build -j2 --target octomap-rt-bigmap-bench
#   rm -rf .device-bundle/replica-s11 && mkdir -p .device-bundle/replica-s11/bin
#   cp build/tools/bigmap_bench/octomap-rt-bigmap-bench .device-bundle/replica-s11/bin/
#   strip .device-bundle/replica-s11/bin/*
#   ../shared/device/bundle-libs .device-bundle/replica-s11 .device-bundle/replica-s11/bin/*
# There: OUT=$OUT/replica bash docs/bench/gpu/issue23-clients.sh, carry [".device-bundle/replica-s11"], a call of
# 300 s; the result comes back as replica-s11.tar.gz (progress.txt, grow.txt, run-*.txt, runs.csv, machine.txt).
. docs/bench/gpu/lib.sh ${BUNDLE:-replica-s11}
B=$N/bin/octomap-rt-bigmap-bench
E=(-r 0.1 --backend ${BACKEND:-vulkan} --preset campus --scan-scale 0.1)
log grow
timeout 25 "$B" grow "${E[@]}" --point-scale ${GROW_POINT_SCALE:-1} --target-nodes ${TARGET_NODES:-9000000} \
  --map "$T/big.ot" > "$O/grow.txt" 2>&1
echo "rc=$?" >> "$O/grow.txt"
R=(--map "$T/big.ot" --stream-point-scale ${STREAM_POINT_SCALE:-0.25} --producers 3 --rate 3 --duration ${DURATION:-15}
   --drain-timeout ${DRAIN:-30})
# run NAME CAP ARGS: at most CAP s and never past END s into the call (the result is packed at exit).
END=${END:-285}
run() { local name=$1 cap=$2; shift 2; log "run-$name"; local t=$((END - (SECONDS - start))); [ "$t" -gt "$cap" ] && t=$cap
  timeout "$t" "$B" run "${E[@]}" "${R[@]}" "$@" > "$O/run-$name.txt" 2>&1
  echo "rc=$?" >> "$O/run-$name.txt"; }
left 40 && run off 70 --readers off --read-replica off
left 110 && run on-3 75 --readers on --read-replica on --query-clients 3
left 185 && run on-1 75 --readers on --read-replica on --query-clients 1
left 235 && run on-3-b5 60 --readers on --read-replica on --query-clients 3 --replica-batch-ms 5
grep -h '^csv' "$O"/run-*.txt > "$O/runs.csv" 2>/dev/null
exit 0
