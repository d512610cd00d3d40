#!/usr/bin/env bash
# The benchmark suite of docs/BENCHMARKS.md on this machine: every preset (scaled to fit a
# 2-core machine), the real data sets, 4 resolutions, every back end, both octree stages,
# then the accuracy runs (exact traversal). Writes CSV, Markdown and PNG charts into OUTDIR.
#
#   tools/bench/run-bench.sh OUTDIR            # this machine's suite (~15-30 min on 2 cores)
#   SCALE_FACTOR=4 tools/bench/run-bench.sh D  # 4x more scans per preset (faster machines)
#
# Environment: OCTOMAP_RT_BIN (default build/client/octomap-rt), OCTOMAP_RT_DATA (default
# ../shared/data), RESOLUTIONS (default 0.1,0.2,0.4,0.8).
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
out=${1:?usage: run-bench.sh OUTDIR}
bin=${OCTOMAP_RT_BIN:-$repo/build/client/octomap-rt}
data=${OCTOMAP_RT_DATA:-$repo/../shared/data}
res=${RESOLUTIONS:-0.1,0.2,0.4,0.8}
f=${SCALE_FACTOR:-1}
mkdir -p "$out"
scale() { awk -v s="$1" -v f="$f" 'BEGIN { v = s * f; if (v > 1) v = 1; print v }'; }

common=(--resolutions "$res" --backends cpu,cpu-grid,vulkan,rt --traversals octomap
        --octree sequential,batched --warmup 1)
# Scans kept per preset (full points per scan, so every scan costs what the paper's does):
# fr079 7 of 66, campus 2 of 81 (its 60 m rays make OctoMap slow), skt-corridor 9 of 305.
run() {  # name, scan scale, extra flags...
  local name=$1 s; s=$(scale "$2"); shift 2
  echo "== $name (scan scale $s) ==" >&2
  "$bin" bench "$@" --scan-scale "$s" --point-scale 1 "${common[@]}" \
    --csv "$out/$name.csv" --markdown "$out/$name.md" || echo "run-bench: $name exited with $?" >&2
}
run fr079 0.1 --preset fr079
run campus 0.025 --preset campus
run skt-corridor 0.03 --preset skt-corridor
if [ -d "$data" ]; then
  run real 0.1 --preset none --data "$data"
fi
# Accuracy (paper Fig. 10): exact traversal against OctoMap at 0.1 m.
echo "== accuracy (exact traversal) ==" >&2
"$bin" bench --preset fr079,campus,skt-corridor --scan-scale "$(scale 0.03)" --point-scale 1 --resolutions 0.1 \
  --backends vulkan --traversals octomap,exact --octree batched \
  --csv "$out/accuracy.csv" --markdown "$out/accuracy.md" || echo "run-bench: accuracy exited with $?" >&2

csvs=$(ls "$out"/fr079.csv "$out"/campus.csv "$out"/skt-corridor.csv "$out"/real.csv 2>/dev/null | paste -sd, -)
"$bin" bench --replot "$csvs" --markdown "$out/all.md" --png "$out/charts"
echo "run-bench: results in $out (all.md, accuracy.md, charts/*.png)" >&2
