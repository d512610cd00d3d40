#!/bin/bash
# Issue 23 (helper replica, 2026-12-02 session 3): does the read replica keep up, and what does it cost mapping,
# on the dev machine (2 cores, cpu-grid back end). From the repository root, with a build that has
# octomap-rt-bigmap-bench:
#     MAP=/tmp/issue23-bigmap-6M.ot docs/bench/dev/issue23-replica.sh build docs/bench/dev/issue23-replica
# (The team's rule on the shared machine: run it under `nice -n 10`; the replica's nice step is relative, so its
# thread then runs at 19.) The map: docs/bench/dev/issue23-bigmap.sh's (grown here when $MAP does not exist). Fresh in-process daemons on
# it, alternated in every round so that the machine's load hits each alike:
#   off        readers off (no snapshot, autosave, viewer map or queries), no replica: the baseline
#   after      readers on, the read replica as the server runs it (scans that wait applied together, its
#              thread 10 nice steps below the server, its octree stage's helpers at the lowest priority)
#   nover      readers on, the replica without versions for whole-map readers (they copy it under its lock:
#              the design before session 5; `after` reads versions kept per region, octree/versions/map_version.h)
#   nice0      readers on, the replica as above but at the server's priority (what the nice step buys)
#   unbatched  readers on, the replica one scan per update on one thread at the server's priority (the design
#              before: a quarter of the cores, at least one)
# "readers on" here is the issue's dev case: a fresh snapshot every 10 s, autosave every 10 s, the viewer map at
# 1 Hz, 100 point queries a second. Then one round with a snapshot every second (the H200's case):
# before (readers copy under the map lock, no replica) and after.
set -u
build=$1 out=$2
mkdir -p "$out"
B=$build/tools/bigmap_bench/octomap-rt-bigmap-bench
E=(-r 0.1 --backend cpu-grid --preset campus --scan-scale 0.1)
map=${MAP:-${TMPDIR:-/tmp}/issue23-bigmap-$$.ot}
{ date -u; nproc; uptime; } > "$out/machine.txt"
[ -f "$map" ] || "$B" grow "${E[@]}" --point-scale 0.2 --target-nodes 5000000 --map "$map" > "$out/grow.txt" 2>&1
R=(--map "$map" --stream-point-scale 0.01 --producers 3 --rate 0.2 --duration 40)
run() { local name=$1; shift; "$B" run "${E[@]}" "${R[@]}" "$@" > "$out/run-$name.txt" 2>&1; uptime >> "$out/machine.txt"; }
# RUNS picks the kinds of run (default off after nice0 unbatched), e.g. RUNS="off nover after" for session 5's.
has() { case " ${RUNS:-off after nice0 unbatched} " in *" $1 "*) return 0;; esac; return 1; }
for round in ${ROUNDS:-a b c}; do
  has off && run "off-$round" --readers off --read-replica off
  has after && run "after-$round" --readers on --read-replica on --snapshot-period 10
  has nover && run "nover-$round" --readers on --read-replica on --snapshot-period 10 --replica-versions off
  has nice0 && run "nice0-$round" --readers on --read-replica on --snapshot-period 10 --replica-nice 0
  has unbatched && run "unbatched-$round" --readers on --read-replica on --snapshot-period 10 --replica-batch-voxels 0 --replica-nice 0 --replica-threads 1
done
if [ -z "${SKIP_SNAPSHOT_1S:-}" ]; then
  run before-1s --readers on --read-replica off --snapshot-period 1
  has nover && run nover-1s --readers on --read-replica on --snapshot-period 1 --replica-versions off
  run after-1s --readers on --read-replica on --snapshot-period 1
fi
grep -H '^csv' "$out"/run-*.txt | sed 's|^.*/run-||; s|\.txt:csv|,csv|' > "$out/runs.csv"
{ date -u; uptime; } >> "$out/machine.txt"
