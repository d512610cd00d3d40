#!/bin/bash
# fr079-real: old default, old with --threads 1 (one walk thread, one octree thread, no yielding
# helper), new default, alternated; OLD and NEW as in ../ab.sh. Run from a worktree root.
set -u
O=${1:-/tmp/threads1}; mkdir -p $O
OLD=${OLD:?}; NEW=${NEW:?}
C="--resolutions 0.1 --backends cpu-grid --traversals octomap --octree batched --no-octomap-breakdown --repeat 3 --preset fr079-real"
for k in a b; do
  uptime >> $O/load.txt; $OLD bench $C --data ../shared/data --csv $O/old-default-$k.csv > /dev/null 2>&1
  uptime >> $O/load.txt; $OLD bench $C --threads 1 --data ../shared/data --csv $O/old-threads1-$k.csv > /dev/null 2>&1
  uptime >> $O/load.txt; $NEW bench $C --data ../shared/data --csv $O/new-default-$k.csv > /dev/null 2>&1
done
uptime >> $O/load.txt
