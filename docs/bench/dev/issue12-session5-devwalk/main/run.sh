#!/bin/bash
set -u
O=${1:-/tmp/main-ab}; mkdir -p $O; OLD=${OLD:?}; NEW=${NEW:?}
C="--resolutions 0.1 --backends cpu-grid --traversals octomap --octree batched --no-octomap-breakdown --repeat 3 --preset fr079-real"
# run from a worktree root
for k in a b; do
  uptime >> $O/load.txt; $OLD bench $C --data ../shared/data --csv $O/old-$k.csv > /dev/null 2>&1
  uptime >> $O/load.txt; $NEW bench $C --data ../shared/data --csv $O/new-$k.csv > /dev/null 2>&1
done
uptime >> $O/load.txt
