#!/usr/bin/env bash
# The benchmark suite on the GPU machine, from the bundled binary (no ../shared needed: the
# presets are generated in the process). Writes CSV (and the Markdown tables) under $OUT;
# gnuplot is usually absent there, so chart the CSV here afterwards:
#   tools/bench/plot.sh OUTDIR FILE.csv...
#
# On this machine, once per build:
#   mkdir -p .device-bundle/bin && cp build/client/octomap-rt .device-bundle/bin/
#   ../shared/device/bundle-libs .device-bundle .device-bundle/bin/*
#   # optional real data: mkdir -p .device-data && cp -r ../shared/data/{3dtk_dat,octomap_share} .device-data/
# There (one `run` call each, carrying .device-bundle and, if wanted, .device-data; each fits
# in the 10-minute limit of one call):
#   . .device-bundle/env.sh .device-bundle; tools/bench/device-bench.sh headline
#   . .device-bundle/env.sh .device-bundle; tools/bench/device-bench.sh sweep fr079
#   . .device-bundle/env.sh .device-bundle; tools/bench/device-bench.sh accuracy
#
# Suites:
#   headline [PRESET...]  0.1 m; each preset at the scale below; all back ends, batched octree,
#                         both traversals (rt does exact only). One preset per call is safest.
#   sequential [PRESET...] vulkan with OctoMap's updateNode loop as the octree stage (Amdahl)
#   sweep PRESET...       0.1, 0.2, 0.4, 0.8 m for the Fig. 6 chart; octomap traversal
#   accuracy              exact traversal against OctoMap at 0.1 m (Fig. 10)
#   real                  the real data sets in .device-data (3dtk, scan_dat, fr079-real)
# Environment: BIN (default .device-bundle/bin/octomap-rt), OUT (default ./bench-out),
# FR079_SCALE, CAMPUS_SCALE, SKT_SCALE (scan shares; defaults keep each preset's OctoMap run
# around a minute on one core), POINT_SCALE (share of points per scan, default 1), EXTRA
# (more flags for bench).
set -euo pipefail
suite=${1:-headline}; shift || true
bin=${BIN:-.device-bundle/bin/octomap-rt}
out=${OUT:-./bench-out}
mkdir -p "$out"
declare -A scale=([fr079]=${FR079_SCALE:-1} [campus]=${CAMPUS_SCALE:-0.1} [skt-corridor]=${SKT_SCALE:-0.2}
                  [fr079-real]=${FR079_SCALE:-1})
presets=("$@")
[ ${#presets[@]} -gt 0 ] || presets=(fr079 campus skt-corridor)
{ nproc; grep -m1 'model name' /proc/cpuinfo; nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null || true; } > "$out/machine.txt"
bench() {  # preset, tag, flags...
  local p=$1 tag=$2; shift 2
  echo "== $suite $p (scan scale ${scale[$p]}) ==" >&2
  "$bin" bench --preset "$p" --scan-scale "${scale[$p]}" --point-scale "${POINT_SCALE:-1}" --warmup 1 "$@" ${EXTRA:-} \
    --csv "$out/$tag-$p.csv" --markdown "$out/$tag-$p.md" || echo "device-bench: $p exited with $?" >&2
}
case $suite in
  headline)
    for p in "${presets[@]}"; do
      bench "$p" headline --resolutions 0.1 --backends cpu-grid,vulkan,rt --traversals octomap,exact --octree batched
    done ;;
  sequential)
    for p in "${presets[@]}"; do
      bench "$p" sequential --resolutions 0.1 --backends vulkan --traversals octomap --octree sequential \
        --no-octomap-breakdown
    done ;;
  sweep)
    for p in "${presets[@]}"; do
      bench "$p" sweep --resolutions 0.1,0.2,0.4,0.8 --backends cpu-grid,vulkan --traversals octomap --octree batched
    done ;;
  accuracy)
    for p in "${presets[@]}"; do
      bench "$p" accuracy --resolutions 0.1 --backends vulkan,rt --traversals exact --octree batched --no-octomap-breakdown
    done ;;
  real)
    [ -d .device-data ] || { echo "device-bench: carry .device-data for the real data sets" >&2; exit 2; }
    "$bin" bench --preset none --data .device-data --scan-scale "${FR079_SCALE:-1}" --resolutions 0.1,0.2 \
      --backends cpu-grid,vulkan,rt --traversals octomap,exact --octree batched ${EXTRA:-} \
      --csv "$out/real.csv" --markdown "$out/real.md" || echo "device-bench: real exited with $?" >&2 ;;
  *) echo "device-bench: unknown suite '$suite' (headline, sequential, sweep, accuracy, real)" >&2; exit 2 ;;
esac
ls -l "$out" >&2
