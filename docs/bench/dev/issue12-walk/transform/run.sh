#!/bin/bash
cd /work/wt/ground
C="--resolutions 0.1 --backends cpu-grid --traversals octomap --octree batched --repeat 3 --no-octomap-breakdown"
run() { local n=$1 v=$2; shift 2
  echo "== $v $n $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)"
  /tmp/walk/octomap-rt.$v bench $C "$@" --csv /tmp/walk/h_${v}_${n}.csv 2>&1 | grep -E "@"; }
for i in 1 2; do for v in final tf; do
  run real_$i $v --preset none --data ../shared/data
  run skt_$i $v --preset skt-corridor --scan-scale 0.1
done; done
echo MEASURE_DONE
