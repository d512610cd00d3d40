#!/bin/bash
# Alternates main's octree code before this work (old) and the final code (new2) on the dev machine.
O=/tmp/octree/meas2; mkdir -p $O; cd /work/wt/perf
C="--resolutions 0.1 --backends cpu-grid --traversals octomap --octree batched --no-octomap-breakdown"
for round in 1 2 3; do
  for v in old new2; do
    B=/tmp/octree/$v
    echo "### round $round $v $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)" >> $O/octree-bench.txt
    $B/octomap-rt-octree-bench --threads 1 2 --repeat 3 --passes 1 >> $O/octree-bench.txt 2>&1
    $B/octomap-rt-octree-bench --data /tmp/octree --graph fr079s.graph --threads 1 2 --repeat 3 --passes 1 >> $O/octree-bench.txt 2>&1
    echo "### round $round $v $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)" >> $O/bench.txt
    $B/octomap-rt bench $C --repeat 3 --preset fr079 --scan-scale 0.1 --csv $O/fr079-$v-$round.csv >> $O/bench.txt 2>&1
  done
done
echo done >> $O/bench.txt
