#!/bin/bash
O=/tmp/walk3/ab2
cd /work/wt/ground
C="--resolutions 0.1 --backends cpu-grid --traversals octomap --octree batched --no-octomap-breakdown --repeat 3"
run() { local tag=$1 b=$2; shift 2; uptime >> $O/load.txt; echo "$(date -u +%T) $b $tag" >> $O/load.txt
  /usr/bin/time -f "%U %S %e" -o $O/$b-$tag.time /tmp/walk3/octomap-rt.$b bench $C "$@" --csv $O/$b-$tag.csv > $O/$b-$tag.out 2>&1; }
for k in 1 2; do for b in base new; do
  run skt$k $b --preset skt-corridor --scan-scale 0.1
  run fr079$k $b --preset fr079 --scan-scale 0.1
done; done
for k in 1 2; do for b in base new; do
  run real$k $b --preset none --data ../shared/data
  run skt1t$k $b --preset skt-corridor --scan-scale 0.1 --threads 1
done; done
uptime >> $O/load.txt
