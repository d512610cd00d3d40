#!/bin/bash
# lead's final device call (issue 12): main's build; the daemon goal (skt-corridor 0.2, 3 producers x 100 Hz)
# and the bench presets, each with jemalloc's default and with transparent huge pages (MALLOC_CONF).
B=$PWD/.device-bundle/lead
. $B/env.sh $B
export PATH=$B/bin:$PATH
O=/tmp/lead-out; T=/tmp/lead-tmp; mkdir -p $O $T
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" >> $O/progress.txt; }
finish() { log done; uptime >> $O/machine.txt; tar -czf "$OUT/lead-final.tar.gz" -C $O . ; exit 0; }
trap finish EXIT
{ date -u; nproc; nvidia-smi -L; nvidia-smi --query-gpu=driver_version --format=csv,noheader; uptime; lscpu | grep 'Model name';
  cat /sys/kernel/mm/transparent_hugepage/enabled; } > $O/machine.txt 2>&1
THP="MALLOC_CONF=thp:always,metadata_thp:always"
left() { [ $((SECONDS - start)) -lt $1 ]; }
# --- the daemon
log scenegen; $B/bin/octomap-rt-scenegen skt-corridor --scan-scale 0.2 -o $T/skt02.graph > $O/scenegen.txt 2>&1
daemon() { local tag=$1 rep=$2 rounds=$3; log daemon-$tag
  OCTOMAP_RT_BUILD_DIR=$B/bin timeout 60 $B/server-bench --graph $T/skt02.graph --repeat $rep --rounds $rounds --modes on \
    --rate 100 -- -r 0.1 --backend vulkan > $O/daemon-$tag.txt 2>&1; }
daemon x5 5 2
daemon x20 20 1
# --- the bench presets
C="--resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown"
bench() { local name=$1; shift; log bench-$name; echo "### $name: $*" >> $O/bench.txt
  timeout 150 env $BENV $B/bin/octomap-rt bench $C "$@" --csv $O/$name.csv >> $O/bench.txt 2>&1; echo "rc=$?" >> $O/bench.txt; }
BENV=X=1 bench fr079 --preset fr079
BENV=$THP bench fr079-thp --preset fr079
left 300 && BENV=X=1 bench campus --preset campus --scan-scale 0.1
left 390 && BENV=$THP bench campus-thp --preset campus --scan-scale 0.1
left 450 && BENV=X=1 bench skt --preset skt-corridor --scan-scale 0.2
left 480 && BENV=X=1 bench real --preset none --data .device-data --repeat 3
exit 0
