#!/bin/bash
# Helper devwalk, fifth session: old (main 9e54710) and new (perf 12edcbb before its rebase on
# octree2's work: 69d117f + ff5d711 + the keys_hold_ends change) alternated, with the lead's
# idle4 command lines (docs/bench/dev/issue12-idle4/run.sh). OLD and NEW are the two builds'
# build/client/octomap-rt; run from a worktree root (../shared/data).
set -u
O=$1; shift; mkdir -p $O
OLD=${OLD:?path to the old octomap-rt}; NEW=${NEW:?path to the new octomap-rt}
C="--resolutions 0.1 --backends cpu-grid --traversals octomap --octree batched --no-octomap-breakdown"
for k in "$@"; do
  for v in old new; do
    B=$OLD; [ $v = new ] && B=$NEW
    uptime >> $O/load.txt
    $B bench $C --repeat 3 --preset none --data ../shared/data --csv $O/real-$v-$k.csv > $O/real-$v-$k.out 2>&1
  done
done
for k in "$@"; do
  for v in old new; do
    B=$OLD; [ $v = new ] && B=$NEW
    uptime >> $O/load.txt
    $B bench $C --repeat 3 --preset fr079 --scan-scale 0.1 --csv $O/fr079-$v-$k.csv > $O/fr079-$v-$k.out 2>&1
    $B bench $C --repeat 3 --preset skt-corridor --scan-scale 0.1 --csv $O/skt-$v-$k.csv > $O/skt-$v-$k.out 2>&1
  done
done
uptime >> $O/load.txt
