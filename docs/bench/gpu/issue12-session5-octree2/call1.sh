#!/bin/bash
# helper octree2's first device call of the fifth session (issue 12): fr079 (66 scans, 0.1 m, vulkan, batched,
# pipelined) with main 9e54710's octomap-rt (old) and the octree stage whose jobs are shared out (new: bucketing
# passes in chunks from a counter, threads that come late skip a job), alternating, on the idle machine and beside
# 4 busy-loop processes (a "slow machine": 15 octree workers + stage 1 + 4 loops on 16 cores). --repeat 3: each
# process's figure is the median of 3 timed runs; OctoMap once per process. /proc/stat before and after each run.
B=$PWD/.device-bundle/octree2
. $B/env.sh $B
O=/tmp/octree2-out; mkdir -p $O
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" >> $O/progress.txt; }
LOAD=()
unload() { for p in "${LOAD[@]}"; do kill "$p" 2>/dev/null; done; for p in "${LOAD[@]}"; do wait "$p" 2>/dev/null; done; LOAD=(); }
finish() { unload; log done; uptime >> $O/machine.txt; tar -czf "$OUT/octree2-call1.tar.gz" -C $O . ; exit 0; }
trap finish EXIT
{ date -u; nproc; nvidia-smi -L; uptime; lscpu | grep -E 'Model name|Hypervisor|MHz'; cat /sys/kernel/mm/transparent_hugepage/enabled;
  top -bn1 | head -15; } > $O/machine.txt 2>&1
left() { [ $((SECONDS - start)) -lt $1 ]; }
load() { for i in $(seq 1 $1); do ( while :; do :; done ) & LOAD+=($!); done; }
C="--resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown --repeat 3"
bench() { local name=$1 v=$2 k=$3; log "bench $name ($v, load $k)"; echo "### $name: $v load $k" >> $O/bench.txt
  echo "before $(head -1 /proc/stat)" >> $O/bench.txt; [ "$k" -gt 0 ] && load "$k"
  timeout 100 $B/bin/octomap-rt-$v bench $C --preset fr079 --csv $O/$name.csv >> $O/bench.txt 2>&1; echo "rc=$?" >> $O/bench.txt
  unload; echo "after $(head -1 /proc/stat)" >> $O/bench.txt; }
# The fresh machine's first process is slow (fourth session, call 2): a short throw-away run first.
log warm; timeout 60 $B/bin/octomap-rt-new bench $C --preset fr079 --scan-scale 0.1 > $O/warm.txt 2>&1
bench old-idle-1 old 0;  bench new-idle-1 new 0;  bench new-load-1 new 4;  bench old-load-1 old 4
left 300 && { bench new-idle-2 new 0;  bench old-idle-2 old 0;  bench old-load-2 old 4;  bench new-load-2 new 4; }
left 360 && { bench old-idle-3 old 0;  bench new-idle-3 new 0; }
left 400 && { bench new-load-3 new 4;  bench old-load-3 old 4; }
exit 0
