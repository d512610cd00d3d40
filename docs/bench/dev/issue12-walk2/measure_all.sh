#!/bin/bash
cd /work/wt/ground
O=$1; R=$2; shift 2
mkdir -p $O
C="--resolutions 0.1 --backends cpu-grid --traversals octomap --octree batched --repeat 3 --no-octomap-breakdown"
run() { local n=$1 v=$2; shift 2
  echo "== $v $n $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)"
  /usr/bin/time -f "$v $n: %U s user, %e s wall" /tmp/walk2/octomap-rt.$v bench $C "$@" --csv $O/${v}_${n}.csv 2>&1 | grep -E "user|@"
}
for i in $(seq 1 $R); do for v in "$@"; do
  run fr079_$i $v --preset fr079 --scan-scale 0.1
  run fr079t1_$i $v --preset fr079 --scan-scale 0.1 --threads 1
  run real_$i $v --preset none --data ../shared/data
  run skt_$i $v --preset skt-corridor --scan-scale 0.1
done; done
echo MEASURE_DONE
