#!/bin/bash
# lead's third device call of the fourth session (issue 12): fr079 again on another fresh machine, new (main
# 202dc47) and old (main a4c5234) alternating, to see whether the first process on a fresh machine is slow again
# (call 2's first run: 38.4x), then the real sets once more.
N=$PWD/.device-bundle/lead; OLD=$PWD/.device-bundle/old
. $N/env.sh $N
export PATH=$N/bin:$PATH
O=/tmp/lead-out; T=/tmp/lead-tmp; mkdir -p $O $T
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" >> $O/progress.txt; }
finish() { log done; uptime >> $O/machine.txt; tar -czf "$OUT/lead-call3.tar.gz" -C $O . ; exit 0; }
trap finish EXIT
{ date -u; nproc; nvidia-smi -L; nvidia-smi --query-gpu=driver_version --format=csv,noheader; uptime; lscpu | grep 'Model name';
  cat /sys/kernel/mm/transparent_hugepage/enabled; } > $O/machine.txt 2>&1
left() { [ $((SECONDS - start)) -lt $1 ]; }
C="--resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown"
bench() { local name=$1 bin=$2; shift 2; log bench-$name; echo "### $name: $*" >> $O/bench.txt
  timeout 150 $bin/bin/octomap-rt bench $C "$@" --csv $O/$name.csv >> $O/bench.txt 2>&1; echo "rc=$?" >> $O/bench.txt; }
bench fr079-new-a $N --preset fr079
bench fr079-old-a $OLD --preset fr079
bench fr079-new-b $N --preset fr079
bench fr079-old-b $OLD --preset fr079
bench fr079-new-c $N --preset fr079
left 150 && bench real $N --preset none --data .device-data --repeat 3
exit 0
