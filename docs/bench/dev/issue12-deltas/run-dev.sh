#!/bin/bash
# dev machine: stage 2 per scan, old (main f6b0a40) vs new (perf), alternating
cd /work/wt/perf
O=/tmp/deltas/dev
/tmp/deltas/new/octomap-rt-scenegen skt-corridor --scan-scale 0.1 -o /tmp/deltas/dev/skt01.graph > $O/scenegen.txt 2>&1
for r in a b; do
  for b in old new; do
    echo "== $(date -u +%T) $b-$r" >> $O/progress.txt
    OCTOMAP_RT_BUILD_DIR=/tmp/deltas/$b tools/server-bench/server-bench --graph /tmp/deltas/dev/skt01.graph --repeat 2 \
      --rounds 1 --modes on --rate 1 -- -r 0.1 --backend cpu-grid > $O/daemon-$b-$r.txt 2>&1
  done
done
echo "== $(date -u +%T) done" >> $O/progress.txt
