#!/bin/bash
# pipebench device call 1: where campus' and fr079's time goes (no OctoMap runs).
B=$(cd "$(dirname "$0")" && pwd)
. $B/env.sh $B
export PATH=$B/bin:$PATH
O=$OUT; T=/tmp/pb; mkdir -p $T
log() { echo "== $(date -u +%T) $*" >> $O/progress.txt; }
{ date -u; nproc; nvidia-smi -L; uptime; lscpu | head -20; free -g; } > $O/machine.txt 2>&1
log gen; octomap-rt-scenegen campus --scan-scale ${CS:-0.1} -o $T/campus.graph > $T/gen.txt 2>&1
octomap-rt-scenegen fr079 --scan-scale ${FS:-1} -o $T/fr079.graph >> $T/gen.txt 2>&1
log gen-done
R="-r 0.1 --backend vulkan -q"
run() { local name=$1; shift; log $name; echo "### $name: $*" >> $O/runs.txt; timeout 60 octomap-rt build $R "$@" >> $O/runs.txt 2>&1; echo "rc=$?" >> $O/runs.txt; }
for d in campus fr079; do
  run $d-pipe-1 $T/$d.graph -o $T/m.ot
  run $d-pipe-2 $T/$d.graph -o $T/m.ot
  run $d-seq-1 $T/$d.graph -o $T/m.ot --no-pipeline
  run $d-pipe-t8 $T/$d.graph -o $T/m.ot --threads 8
  run $d-seq-t8 $T/$d.graph -o $T/m.ot --threads 8 --no-pipeline
  run $d-pipe-3 $T/$d.graph -o $T/m.ot
done
uptime >> $O/machine.txt
for d in campus fr079; do
  log perf-$d
  timeout 60 perf record -F 1999 -o $T/$d.perf -- octomap-rt build $R $T/$d.graph -o $T/m.ot > $O/perf-$d-run.txt 2>&1
  perf report -i $T/$d.perf --sort sym --stdio 2>/dev/null | grep -v '^#' | head -70 > $O/perf-$d-sym.txt
  perf report -i $T/$d.perf --sort pid --stdio 2>/dev/null | grep -v '^#' | head -30 > $O/perf-$d-tid.txt
  perf report -i $T/$d.perf --sort pid,sym --stdio 2>/dev/null | grep -v '^#' | head -120 > $O/perf-$d-tidsym.txt
done
log done
cd $O && tar czf prof1.tgz *.txt && ls -la >> $O/progress.txt
