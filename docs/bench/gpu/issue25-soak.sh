#!/bin/bash
# Issue 25's soak on the GPU machine, one device call of at most 8 minutes: 4 robots x 10 Hz
# circling the fr079-real preset (OctoMap's real FR-079 map seen by a simulated LiDAR, full
# 89k-point scans) for 7 minutes against octomap-rt-server on the vulkan back end with decay,
# clearing and the memory bound on (--max-map-memory $BOUND, default 8MiB, the dev soak's; BOUND=0:
# decay and clearing only, as the 2026-12-01 run); the server's RSS, map memory (as the bound
# counts it), evicted bytes and end-to-end p99 at every status (0.5 s), the bound's cost
# breakdown every 10 s in server.log ("memory bound costs").
# SECS (default 420) and SETTLE (default 30): a shorter soak for one step of a shared call,
# e.g. SECS=90 SETTLE=15 (~2 min in all); each soak is cut at SECS + SETTLE + 25 s and skipped,
# not started, once it could end past LIMIT (default 470) s of the call. BOUNDS="8MiB 0": one soak per bound, one
# after the other, each in its own folder bound-B/ (the p99 with the bound beside the p99
# without it, in one call); BUNDLE: the bundle's name (default issue25; the result NAME.tar.gz).
#
# Here, first (from the repository root, after building the three targets):
#   cmake --build build --target octomap-rt-server octomap-rt-loadtest octomap-rt-scenegen
#   mkdir -p .device-bundle/issue25/bin .device-data/octomap_share
#   cp build/server/octomap-rt-server build/tools/loadtest/octomap-rt-loadtest \
#      build/tools/scenegen/octomap-rt-scenegen "$(command -v ip)" .device-bundle/issue25/bin/
#   ../shared/device/bundle-libs .device-bundle/issue25 .device-bundle/issue25/bin/*
#   cp ../shared/data/octomap_share/geb079.bt .device-data/octomap_share/
# The device call: carry [".device-bundle", ".device-data"], command
#   bash docs/bench/gpu/issue25-soak.sh        (timeout 480 s)
# Back here: mkdir -p docs/bench/gpu/issue25-soak-bound && tar -xzf <files_at>/issue25.tar.gz -C docs/bench/gpu/issue25-soak-bound/
#   docs/bench/dev/issue25-soak/plot.sh docs/bench/gpu/issue25-soak-bound/series.csv \
#     docs/bench/gpu/issue25-soak-bound/soak.png "fr079-real, 4 robots x 10 Hz, H200, decay, bound 8MiB"
#   docs/bench/dev/issue25-soak/figures.py docs/bench/gpu/issue25-soak-bound 8
. docs/bench/gpu/lib.sh "${BUNDLE:-issue25}"
secs=${SECS:-420}
settle=${SETTLE:-30}
( while :; do echo "$(date -u +%T) $(cut -d' ' -f1-3 /proc/loadavg) $(nproc)"; sleep 15; done ) > "$O/load.txt" &
load_pid=$!
# soak BOUND DIR: one loadtest run into DIR.
soak() {
  local bound=$1 dir=$2 extra=()
  if ! left $((${LIMIT:-470} - secs - settle - 25)); then
    log "soak $bound skipped: too little of the call left"
    return
  fi
  log "soak bound $bound, $secs s"
  mkdir -p "$dir"
  [ "$bound" = 0 ] || extra=(--map "$T/soak-$bound.ot" --max-map-memory "$bound")
  timeout $((secs + settle + 25)) "$N/bin/octomap-rt-loadtest" --server "$N/bin/octomap-rt-server" --producers 4 \
    --rate 10 --duration "$secs" --settle "$settle" --points 89000 --scene fr079-real --data .device-data \
    --series "$dir/series.csv" --log "$dir/server.log" -- -r 0.1 --backend vulkan --decay-half-life 60 \
    --decay-step 5 --clear-radius 20 --clear-recent 30 --clear-period 10 "${extra[@]}" > "$dir/report.txt" 2>&1
  echo "rc=$?" >> "$dir/report.txt"
  du -sb "$T"/soak-"$bound".ot* >> "$dir/report.txt" 2>&1
}
if [ -n "${BOUNDS:-}" ]; then
  for b in $BOUNDS; do soak "$b" "$O/bound-$b"; done
else
  soak "${BOUND:-8MiB}" "$O"
fi
kill "$load_pid"
exit 0
