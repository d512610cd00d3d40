#!/bin/bash
B=$(cd "$(dirname "$0")" && pwd)
. $B/env.sh $B
O=$OUT/r; mkdir -p $O
trap 'cd $OUT && tar czf call4.tgz r && rm -rf r' EXIT
{ date -u; nvidia-smi -L; uptime; } > $O/machine.txt 2>&1
MALLOC_CONF=thp:always,metadata_thp:always timeout 28 $B/bin/octomap-rt bench --resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown --preset fr079 --scan-scale ${FS:-1} > $O/bench-fr079-thp.txt 2>&1
echo "rc=$?" >> $O/bench-fr079-thp.txt
