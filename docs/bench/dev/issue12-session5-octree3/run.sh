#!/bin/bash
# helper octree3, fifth session: the octree stage's per-voxel work, old (main 4aa2fe4, the octree code of 12edcbb,
# binary bench-old) against new (main 3978efe, bench-new), alternated, on the dev machine (2 cores,
# shared). Lists: octomap-rt-scenegen fr079 --scan-scale 0.1 -o $D/fr079s.graph and
# octomap-rt-scenegen fr079-real --scan-scale 0.1 --data ../shared/data -o $D/real.graph.
# Per run: perf stat of the whole process (shooting with --backend cpu included, the same code in
# both) and the bench's own best-of-5 stage time.
D=${D:-/tmp/octree3}; O=${O:-$D/perf}; mkdir -p $O
for round in 1 2 3; do
  for g in fr079s real; do
    for v in old new; do
      echo "### $g round $round $v $(date -u +%T) load $(cut -d' ' -f1-3 /proc/loadavg)" >> $O/perf.txt
      perf stat -e cycles:u,instructions:u,task-clock -o $O/stat.tmp \
        $D/bench-$v --data $D --graph $g.graph --threads 1 --repeat 5 --passes 3 --batched-only 2>&1 | grep "batched," >> $O/perf.txt
      grep -E "cycles|instructions|task-clock" $O/stat.tmp >> $O/perf.txt
    done
  done
done
echo done >> $O/perf.txt
