#!/usr/bin/env bash
# The memory bound's benchmark (issue 25; a tool, not CI): the same load twice, without and
# with --max-map-memory, robots circling a scene over udpm in the load test's own network
# namespace; the server's RSS, its tree memory, the evicted bytes and the p99s over time (every
# status, 0.5 s), the machine's load every 30 s beside it, and a summary of both runs.
#   docs/bench/dev/issue25-bound/run.sh BUILD_DIR OUT_DIR [SECONDS] [BOUND] [SCENE] [-- SERVER FLAGS]
# BOUND as --max-map-memory takes it (e.g. 8MiB); SCENE as in docs/bench/dev/issue25-soak/run.sh.
# MODES="off on" by default; MODES=on runs only the bounded run (beside an earlier off run).
# ROUNDS=N alternates the modes N times (off, on, off, on, ...: the machine's load falls on
# both alike); round k's files are series-MODE-rK.csv, report-MODE-rK.txt, server-MODE-rK.log
# (ROUNDS unset: one round, files without the suffix, as before). MODE oldon: the bound on with
# the server of OLD_BUILD (an older build dir: the same load's before/after of a change).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
b=${1:-build}; o=${2:-$here/out}; secs=${3:-240}; bound=${4:-8MiB}; scene=${5:-fr079-real}
shift $(( $# < 5 ? $# : 5 )); [ "${1:-}" = "--" ] && shift
flags=("$@")
[ ${#flags[@]} -gt 0 ] || flags=(-r 0.1 --backend cpu-grid)
data=${OCTOMAP_RT_DATA:-$here/../../../../../shared/data}
maps=$(mktemp -d)
mkdir -p "$o"
( while :; do echo "$(date -u +%T) $(cut -d' ' -f1-3 /proc/loadavg) $(nproc)"; sleep 30; done ) > "$o/load.txt" &
load_pid=$!
trap 'kill $load_pid 2>/dev/null; rm -rf "$maps"' EXIT
for round in $(seq 1 "${ROUNDS:-1}"); do
  suffix=${ROUNDS:+-r$round}
  for mode in ${MODES:-off on}; do
    rm -rf "$maps/$mode.ot" "$maps/$mode.ot".*
    extra=(--map "$maps/$mode.ot")
    [ "$mode" != off ] && extra+=(--max-map-memory "$bound")
    server=$b/server/octomap-rt-server; [ "$mode" = oldon ] && server=${OLD_BUILD:?oldon needs OLD_BUILD}/server/octomap-rt-server
    echo "scene $scene, $secs s, server flags: ${flags[*]} ${extra[*]}" > "$o/report-$mode$suffix.txt"
    "$b/tools/loadtest/octomap-rt-loadtest" --server "$server" --producers 2 --rate 2 \
      --duration "$secs" --points 20000 --scene "$scene" --data "$data" --series "$o/series-$mode$suffix.csv" \
      --log "$o/server-$mode$suffix.log" -- "${flags[@]}" "${extra[@]}" >> "$o/report-$mode$suffix.txt" 2>&1 ||
      echo "loadtest exit $?" >> "$o/report-$mode$suffix.txt"
  done
done
"$here/summary.py" "$o" > "$o/summary.txt"
cat "$o/summary.txt"
[ -n "${ROUNDS:-}" ] || "$here/plot.sh" "$o" "$o/bound.png" "$scene, 2 robots x 2 Hz, $(nproc) cores, bound $bound"
[ -z "${ROUNDS:-}" ] || "$here/plot.sh" "$o" "$o/bound.png" "$scene, 2 robots x 2 Hz, $(nproc) cores, bound $bound (round 1)" -r1
