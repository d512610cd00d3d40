#!/bin/bash
# lead's first device call of the fourth session (issue 12): main a4c5234 as landed (octree-stage work,
# daemon host-work cuts, compact_into_host_memory default, stage-1 core rule: none measured on the H200
# before). Bench presets (octomap-rt has jemalloc's huge pages built in), the real sets, then the daemon
# goal (skt-corridor 0.2, 3 producers x 100 Hz): three new-space runs (--repeat 5) and one steady (--repeat 20).
B=$PWD/.device-bundle/lead
. $B/env.sh $B
export PATH=$B/bin:$PATH
O=/tmp/lead-out; T=/tmp/lead-tmp; mkdir -p $O $T
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" >> $O/progress.txt; }
finish() { log done; uptime >> $O/machine.txt; tar -czf "$OUT/lead-call.tar.gz" -C $O . ; exit 0; }
trap finish EXIT
{ date -u; nproc; nvidia-smi -L; nvidia-smi --query-gpu=driver_version --format=csv,noheader; uptime; lscpu | grep 'Model name';
  cat /sys/kernel/mm/transparent_hugepage/enabled; } > $O/machine.txt 2>&1
left() { [ $((SECONDS - start)) -lt $1 ]; }
C="--resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown"
bench() { local name=$1; shift; log bench-$name; echo "### $name: $*" >> $O/bench.txt
  timeout 150 $B/bin/octomap-rt bench $C "$@" --csv $O/$name.csv >> $O/bench.txt 2>&1; echo "rc=$?" >> $O/bench.txt; }
bench fr079-a --preset fr079
bench fr079-b --preset fr079
bench skt --preset skt-corridor --scan-scale 0.2
bench real --preset none --data .device-data --repeat 3
left 200 && bench campus --preset campus --scan-scale 0.1
log scenegen; $B/bin/octomap-rt-scenegen skt-corridor --scan-scale 0.2 -o $T/skt02.graph > $O/scenegen.txt 2>&1
daemon() { local tag=$1 rep=$2; log daemon-$tag
  OCTOMAP_RT_BUILD_DIR=$B/bin timeout 60 $B/server-bench --graph $T/skt02.graph --repeat $rep --rounds 1 --modes on \
    --rate 100 -- -r 0.1 --backend vulkan > $O/daemon-$tag.txt 2>&1; }
left 420 && daemon x5-a 5
left 460 && daemon x5-b 5
left 500 && daemon x20 20
left 540 && bench fr079-c --preset fr079
exit 0
