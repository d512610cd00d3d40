#!/bin/bash
# Issue 23 (helper mapstate): the big-map benchmark on the dev machine (2 cores, cpu-grid back end), from the
# repository root with a build that has octomap-rt-bigmap-bench:
#     docs/bench/dev/issue23-bigmap.sh build docs/bench/dev/issue23-bigmap
# Grows a campus map to >= 5 M nodes (0.1 m), saves it, then runs fresh in-process daemons on it: readers off;
# readers on with the read replica off (before) and on (after), alternated. Readers: a fresh snapshot every
# second, autosave every 10 s, the OCTOMAP viewer map at 1 Hz, 100 point queries a second.
set -u
build=$1 out=$2
mkdir -p "$out"
B=$build/tools/bigmap_bench/octomap-rt-bigmap-bench
E=(-r 0.1 --backend cpu-grid --preset campus --scan-scale 0.1)
map=${MAP:-${TMPDIR:-/tmp}/issue23-bigmap-$$.ot}
{ date -u; nproc; uptime; } > "$out/machine.txt"
[ -f "$map" ] || "$B" grow "${E[@]}" --point-scale 0.2 --target-nodes 5000000 --map "$map" > "$out/grow.txt" 2>&1
# Small scans at a low rate: on 2 shared cores a campus scan's octree update at 6 M nodes takes seconds.
R=(--map "$map" --stream-point-scale 0.01 --producers 3 --rate 0.2 --duration 40)
for round in ${ROUNDS:-a b}; do
  "$B" run "${E[@]}" "${R[@]}" --readers off --read-replica off > "$out/run-off-$round.txt" 2>&1
  "$B" run "${E[@]}" "${R[@]}" --readers on --read-replica off > "$out/run-before-$round.txt" 2>&1
  "$B" run "${E[@]}" "${R[@]}" --readers on --read-replica on > "$out/run-after-$round.txt" 2>&1
done
grep -h '^csv' "$out"/run-*.txt > "$out/runs.csv"
{ date -u; uptime; } >> "$out/machine.txt"
