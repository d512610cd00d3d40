#!/bin/bash
# pipebench device call 3: the final code against OctoMap in the same process; jemalloc THP on campus's octree stage.
B=$(cd "$(dirname "$0")" && pwd)
. $B/env.sh $B
NEW=$B/bin/octomap-rt; GEN=$B/bin/octomap-rt-scenegen
O=$OUT/r; T=/tmp/pb; mkdir -p $O $T
trap 'cd $OUT && tar czf call3.tgz r && rm -rf r' EXIT
S=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS-S))s $*" >> $O/progress.txt; }
{ date -u; nproc; nvidia-smi -L; nvidia-smi --query-gpu=driver_version --format=csv,noheader; uptime; lscpu | grep 'Model name';
  cat /sys/kernel/mm/transparent_hugepage/enabled /sys/kernel/mm/transparent_hugepage/defrag; } > $O/machine.txt 2>&1
C="--resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown"
bench() { local name=$1; shift; log bench-$name; echo "### $name: $*" >> $O/bench.txt; timeout 150 $NEW bench $C "$@" --csv $O/$name.csv >> $O/bench.txt 2>&1; echo "rc=$?" >> $O/bench.txt; }
bench fr079 --preset fr079 --scan-scale ${FS:-1}
bench campus --preset campus --scan-scale ${CS:-0.1}
uptime >> $O/machine.txt
log gen; $GEN campus --scan-scale ${CS:-0.1} -o $T/campus.graph > $T/gen.txt 2>&1
run() { local name=$1; shift; log $name; echo "### $name: $*" >> $O/builds.txt; timeout 30 "$@" -o $T/m.ot 2>&1 | grep -E 'back end|stage times|compact\+readback:|total:' >> $O/builds.txt; }
R="-r 0.1 --backend vulkan -q $T/campus.graph"
[ $((SECONDS-S)) -lt 125 ] && run campus-thp env MALLOC_CONF=thp:always,metadata_thp:always $NEW build $R
[ $((SECONDS-S)) -lt 138 ] && run campus $NEW build $R
log done
