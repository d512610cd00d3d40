#!/usr/bin/env bash
# Tables and charts from bench CSV files (e.g. measured on the GPU machine, which has no
# gnuplot): writes OUTDIR/tables.md and OUTDIR/charts/<data set>.png.
#   tools/bench/plot.sh OUTDIR FILE.csv...
set -euo pipefail
repo=$(cd "$(dirname "$0")/../.." && pwd)
out=${1:?usage: plot.sh OUTDIR FILE.csv...}; shift
[ $# -gt 0 ] || { echo "plot.sh: no CSV files given" >&2; exit 2; }
bin=${OCTOMAP_RT_BIN:-$repo/build/client/octomap-rt}
mkdir -p "$out"
"$bin" bench --replot "$(IFS=,; echo "$*")" --markdown "$out/tables.md" --png "$out/charts"
echo "plot.sh: $out/tables.md, $out/charts/" >&2
