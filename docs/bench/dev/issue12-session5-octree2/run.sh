#!/bin/bash
# helper octree2, fifth session: the dev machine's goal configuration (--backend auto = cpu-grid, whose octree
# stage runs on one thread beside the walk) before (main 9e54710) and after the shared-out octree jobs, alternated;
# CPU time of each process from /usr/bin/time. O: output folder; OLD/NEW: folders holding each build's octomap-rt.
O=${O:-/tmp/octree2/dev}; mkdir -p $O
C="--resolutions 0.1 --backends cpu-grid --traversals octomap --octree batched --no-octomap-breakdown"
for round in 1 2 3; do
  for v in old new; do
    B=/work/tmp-octree2/$v
    echo "### fr079-0.1 round $round $v $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)" >> $O/bench.txt
    /usr/bin/time -f "cpu %U user %S sys %e wall" -a -o $O/bench.txt \
      $B/octomap-rt bench $C --repeat 3 --preset fr079 --scan-scale 0.1 --csv $O/fr079-$v-$round.csv >> $O/bench.txt 2>&1
  done
done
for round in 1 2; do
  for v in old new; do
    B=/work/tmp-octree2/$v
    echo "### fr079-real round $round $v $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)" >> $O/bench.txt
    /usr/bin/time -f "cpu %U user %S sys %e wall" -a -o $O/bench.txt \
      $B/octomap-rt bench $C --repeat 3 --preset none --data ../shared/data --csv $O/real-$v-$round.csv >> $O/bench.txt 2>&1
  done
done
echo done >> $O/bench.txt
