#!/bin/bash
# lead's third device call (issue 12): main's daemon (jemalloc defaults) again, for the spread of its p99; fr079 once more.
B=$PWD/.device-bundle/lead
. $B/env.sh $B
export PATH=$B/bin:$PATH
O=/tmp/lead-out; T=/tmp/lead-tmp; mkdir -p $O $T
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" >> $O/progress.txt; }
finish() { log done; uptime >> $O/machine.txt; tar -czf "$OUT/lead-final3.tar.gz" -C $O . ; exit 0; }
trap finish EXIT
{ date -u; nproc; nvidia-smi -L; uptime; MALLOC_CONF=stats_print:true $B/bin/octomap-rt-server --help 2>&1 | grep -E 'opt.thp'; } > $O/machine.txt 2>&1
log scenegen; $B/bin/octomap-rt-scenegen skt-corridor --scan-scale 0.2 -o $T/skt02.graph > $O/scenegen.txt 2>&1
daemon() { local tag=$1 rep=$2 rounds=$3; log daemon-$tag
  OCTOMAP_RT_BUILD_DIR=$B/bin timeout 60 $B/server-bench --graph $T/skt02.graph --repeat $rep --rounds $rounds --modes on \
    --rate 100 -- -r 0.1 --backend vulkan > $O/daemon-$tag.txt 2>&1; }
daemon x5-a 5 1
daemon x5-b 5 1
daemon x5-c 5 1
daemon x20 20 1
C="--resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown"
[ $((SECONDS - start)) -lt 80 ] && { log bench-fr079; timeout 40 $B/bin/octomap-rt bench $C --preset fr079 --csv $O/fr079.csv > $O/bench.txt 2>&1; }
exit 0
