#!/bin/bash
O=/tmp/walk3/ab7
cd /work/wt/ground
C="--resolutions 0.1 --backends cpu-grid --traversals octomap --octree batched --no-octomap-breakdown --repeat 3"
run() { local tag=$1 b=$2; shift 2; uptime >> $O/load.txt; echo "$(date -u +%T) $b $tag" >> $O/load.txt
  /usr/bin/time -f "%U %S %e" -o $O/$b-$tag.time /tmp/walk3/octomap-rt.$b bench $C "$@" --csv $O/$b-$tag.csv > $O/$b-$tag.out 2>&1; }
for b in base final; do run skt1 $b --preset skt-corridor --scan-scale 0.1; run fr0791 $b --preset fr079 --scan-scale 0.1; done
for b in base final; do run real1 $b --preset none --data ../shared/data; done
for b in base final; do run skt2 $b --preset skt-corridor --scan-scale 0.1; run fr0792 $b --preset fr079 --scan-scale 0.1; done
uptime >> $O/load.txt
