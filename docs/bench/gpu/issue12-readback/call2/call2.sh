#!/bin/bash
# pipebench device call 2: readback fix before/after, octree threads while overlapped, OctoMap same process.
B=$(cd "$(dirname "$0")" && pwd)
. $B/env.sh $B
NEW=$B/bin/octomap-rt; OLD=$B/old/octomap-rt; GEN=$B/bin/octomap-rt-scenegen
O=$OUT/r; T=/tmp/pb; mkdir -p $O $T
trap 'cd $OUT && tar czf call2.tgz r && rm -rf r' EXIT
log() { echo "== $(date -u +%T) $*" >> $O/progress.txt; }
{ date -u; nproc; nvidia-smi -L; nvidia-smi --query-gpu=driver_version --format=csv; uptime; lscpu | grep 'Model name'; } > $O/machine.txt 2>&1
log gen; $GEN campus --scan-scale ${CS:-0.1} -o $T/campus.graph > $T/gen.txt 2>&1
$GEN fr079 --scan-scale ${FS:-1} -o $T/fr079.graph >> $T/gen.txt 2>&1
R="-r 0.1 --backend vulkan -q"
run() { local name=$1 bin=$2; shift 2; log $name; echo "### $name: $*" >> $O/builds.txt; timeout 60 $bin build $R "$@" -o $T/m.ot 2>&1 | grep -E 'stage times|compact\+readback:|total:' >> $O/builds.txt; }
for d in fr079 campus; do
  run $d-old-pipe $OLD $T/$d.graph
  run $d-new-pipe $NEW $T/$d.graph
  run $d-new-pipe-t15 $NEW $T/$d.graph --threads 15
  run $d-new-pipe-t12 $NEW $T/$d.graph --threads 12
  run $d-new-pipe-t8 $NEW $T/$d.graph --threads 8
  run $d-new-seq $NEW $T/$d.graph --no-pipeline
  run $d-old-seq $OLD $T/$d.graph --no-pipeline
  run $d-new-pipe-2 $NEW $T/$d.graph
  run $d-new-pipe-t15-2 $NEW $T/$d.graph --threads 15
  run $d-old-pipe-2 $OLD $T/$d.graph
done
uptime >> $O/machine.txt
C="--resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown"
bench() { local name=$1 bin=$2; shift 2; log bench-$name; echo "### $name: $*" >> $O/bench.txt; timeout 170 $bin bench $C "$@" --csv $O/$name.csv >> $O/bench.txt 2>&1; echo "rc=$?" >> $O/bench.txt; }
bench fr079-new $NEW --preset fr079 --scan-scale ${FS:-1}
bench fr079-old $OLD --preset fr079 --scan-scale ${FS:-1}
bench fr079-new-t15 $NEW --preset fr079 --scan-scale ${FS:-1} --threads 15
bench campus-new $NEW --preset campus --scan-scale ${CS:-0.1}
bench campus-old $OLD --preset campus --scan-scale ${CS:-0.1}
log done; uptime >> $O/machine.txt
