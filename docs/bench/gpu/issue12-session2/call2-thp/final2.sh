#!/bin/bash
# lead's second device call (issue 12): main + jemalloc's huge pages compiled in (server/allocator/jemalloc_options.cpp).
B=$PWD/.device-bundle/lead
. $B/env.sh $B
export PATH=$B/bin:$PATH
O=/tmp/lead-out; T=/tmp/lead-tmp; mkdir -p $O $T
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" >> $O/progress.txt; }
finish() { log done; uptime >> $O/machine.txt; tar -czf "$OUT/lead-final2.tar.gz" -C $O . ; exit 0; }
trap finish EXIT
{ date -u; nproc; nvidia-smi -L; uptime; cat /sys/kernel/mm/transparent_hugepage/enabled; MALLOC_CONF=stats_print:true $B/bin/octomap-rt --help 2>&1 | grep -E 'opt.thp|opt.metadata_thp'; } > $O/machine.txt 2>&1
log scenegen; $B/bin/octomap-rt-scenegen skt-corridor --scan-scale 0.2 -o $T/skt02.graph > $O/scenegen.txt 2>&1
daemon() { local tag=$1 rep=$2 rounds=$3; log daemon-$tag
  OCTOMAP_RT_BUILD_DIR=$B/bin timeout 60 $B/server-bench --graph $T/skt02.graph --repeat $rep --rounds $rounds --modes on \
    --rate 100 -- -r 0.1 --backend vulkan > $O/daemon-$tag.txt 2>&1; }
daemon x5 5 2
daemon x20 20 1
C="--resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown"
bench() { local name=$1; shift; log bench-$name; echo "### $name: $*" >> $O/bench.txt
  timeout 150 $B/bin/octomap-rt bench $C "$@" --csv $O/$name.csv >> $O/bench.txt 2>&1; echo "rc=$?" >> $O/bench.txt; }
bench fr079-a --preset fr079
bench fr079-b --preset fr079
bench campus --preset campus --scan-scale 0.1
[ $((SECONDS - start)) -lt 250 ] && bench fr079-c --preset fr079
exit 0
