#!/bin/bash
# lead's last device call of the fourth session (issue 12): main with this session's work (new) against
# main a4c5234 (old, the binaries of call 1) on fr079, alternating; then new alone: campus 0.1 twice,
# skt-corridor 0.2, the real sets, and the daemon goal (skt-corridor 0.2, 3 producers x 100 Hz): three
# new-space runs (--repeat 5, each a fresh daemon) and one steady (--repeat 20). Same options as call 1.
N=$PWD/.device-bundle/lead; OLD=$PWD/.device-bundle/old
. $N/env.sh $N
export PATH=$N/bin:$PATH
O=/tmp/lead-out; T=/tmp/lead-tmp; mkdir -p $O $T
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" >> $O/progress.txt; }
finish() { log done; uptime >> $O/machine.txt; tar -czf "$OUT/lead-call2.tar.gz" -C $O . ; exit 0; }
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
bench skt $N --preset skt-corridor --scan-scale 0.2
bench real $N --preset none --data .device-data --repeat 3
left 230 && bench campus-a $N --preset campus --scan-scale 0.1
log scenegen; $N/bin/octomap-rt-scenegen skt-corridor --scan-scale 0.2 -o $T/skt02.graph > $O/scenegen.txt 2>&1
daemon() { local tag=$1 rep=$2; log daemon-$tag
  OCTOMAP_RT_BUILD_DIR=$N/bin timeout 60 $N/server-bench --graph $T/skt02.graph --repeat $rep --rounds 1 --modes on \
    --rate 100 -- -r 0.1 --backend vulkan > $O/daemon-$tag.txt 2>&1; }
left 400 && daemon x5-a 5
left 420 && daemon x5-b 5
left 440 && daemon x5-c 5
left 460 && daemon x20 20
left 470 && bench campus-b $N --preset campus --scan-scale 0.1
exit 0
