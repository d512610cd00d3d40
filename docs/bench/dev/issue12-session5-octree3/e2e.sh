#!/bin/bash
# helper octree3: the dev machine's goal configuration (--backend auto = cpu-grid, the octree stage on one
# thread beside the walk) on the real sets (3dtk, scan_dat, fr079-real), old (main 4aa2fe4's octree code)
# and new (main 3978efe's) alternated, in one build of the rest (main 3978efe); CPU time of each process
# from /usr/bin/time. Binaries: $D/ort-old, $D/ort-new (octomap-rt).
D=${D:-/tmp/octree3}; O=${O:-$D/e2e}; mkdir -p $O
C="--resolutions 0.1 --backends cpu-grid --traversals octomap --octree batched --no-octomap-breakdown"
for round in 1 2; do
  for v in old new; do
    echo "### real round $round $v $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)" >> $O/bench.txt
    /usr/bin/time -f "cpu %U user %S sys %e wall" -a -o $O/bench.txt \
      $D/ort-$v bench $C --repeat 3 --preset none --data ../shared/data --csv $O/real-$v-$round.csv >> $O/bench.txt 2>&1
  done
done
echo done >> $O/bench.txt
