#!/bin/bash
# lead's fourth device call of the fourth session (issue 12): why fr079's octree stage is 2-4x slower on some
# fresh machines (calls 2 and 3), for old and new code alike. Each run records the CPU's steal time and the
# others' CPU time (/proc/stat) across it, and the processes running before the first; fr079 with the octree
# stage's default threads (15) against --threads 8 and 4 (all CPU stages), alternating.
N=$PWD/.device-bundle/lead
. $N/env.sh $N
O=/tmp/lead-out; mkdir -p $O
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" >> $O/progress.txt; }
finish() { log done; uptime >> $O/machine.txt; tar -czf "$OUT/lead-call4.tar.gz" -C $O . ; exit 0; }
trap finish EXIT
{ date -u; nproc; uptime; lscpu | grep -E 'Model name|Hypervisor|Thread|Core|Socket|NUMA node'; grep MHz /proc/cpuinfo | sort | uniq -c;
  top -bn1 | head -25; } > $O/machine.txt 2>&1
cpu() { head -1 /proc/stat; }
C="--resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown"
bench() { local name=$1; shift; log bench-$name; echo "### $name: $*" >> $O/bench.txt; echo "before $(cpu)" >> $O/bench.txt
  timeout 100 $N/bin/octomap-rt bench $C "$@" --csv $O/$name.csv >> $O/bench.txt 2>&1; echo "rc=$?" >> $O/bench.txt
  echo "after $(cpu)" >> $O/bench.txt; }
bench t0-a --preset fr079
bench t8-a --preset fr079 --threads 8
bench t0-b --preset fr079
bench t4-a --preset fr079 --threads 4
bench t0-c --preset fr079
bench t8-b --preset fr079 --threads 8
exit 0
