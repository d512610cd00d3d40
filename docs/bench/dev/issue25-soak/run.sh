#!/usr/bin/env bash
# Soak benchmark of issue 25 (a tool, not CI): robots circling a scene while the daemon decays
# and clears its map; the server's RSS, its map memory and its end-to-end p99 over time, every
# status message (0.5 s), and the machine's load every 30 s beside it.
#   docs/bench/dev/issue25-soak/run.sh BUILD_DIR OUT_DIR [SECONDS] [SCENE] [-- SERVER FLAGS]
# SCENE: fr079-real (the preset from OctoMap's real FR-079 map), a .graph file (the shared real
# scans) or synthetic. The default server flags are those of docs/BENCHMARKS.md's soak figures.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
b=${1:-build}; o=${2:-$here/out}; secs=${3:-1200}; scene=${4:-fr079-real}
shift $(( $# < 4 ? $# : 4 )); [ "${1:-}" = "--" ] && shift
flags=("$@")
[ ${#flags[@]} -gt 0 ] || flags=(-r 0.1 --backend cpu-grid --decay-half-life 120 --decay-step 10
                                 --clear-radius 20 --clear-recent 60 --clear-period 10)
data=${OCTOMAP_RT_DATA:-$here/../../../../../shared/data}
mkdir -p "$o"
( while :; do echo "$(date -u +%T) $(cut -d' ' -f1-3 /proc/loadavg) $(nproc)"; sleep 30; done ) > "$o/load.txt" &
load_pid=$!
echo "scene $scene, $secs s, server flags: ${flags[*]}" > "$o/report.txt"
"$b/tools/loadtest/octomap-rt-loadtest" --server "$b/server/octomap-rt-server" --producers 2 --rate 2 \
  --duration "$secs" --points 20000 --scene "$scene" --data "$data" --series "$o/series.csv" \
  --log "$o/server.log" -- "${flags[@]}" >> "$o/report.txt" 2>&1 || echo "loadtest exit $?" >> "$o/report.txt"
kill "$load_pid"
"$here/plot.sh" "$o/series.csv" "$o/soak.png" "$scene, 2 robots x 2 Hz, $(nproc) cores"
