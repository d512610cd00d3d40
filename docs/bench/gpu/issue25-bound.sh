#!/bin/bash
# Issue 25's memory bound on the GPU machine, one device call of at most 8 minutes: 4 robots x
# 10 Hz going round the skt-corridor preset (RGB-D corridors, 89k points a scan: a working set
# far smaller than the map) against octomap-rt-server on the vulkan back end, alternating rounds
# of 60 s without and with --max-map-memory 8MiB (off, on, off, on; no decay: the map grows); the
# server's RSS, tree memory, evicted bytes, end-to-end and octree p99 at every status (0.5 s),
# and in server-on-rK.log the bound's cost breakdown every 10 s ("memory bound costs"). The
# server's log says how large the ray space grew (sized from the scans).
#
# Here, first (from the repository root, after building the three targets):
#   cmake --build build --target octomap-rt-server octomap-rt-loadtest octomap-rt-scenegen
#   mkdir -p .device-bundle/issue25b/bin .device-data
#   cp build/server/octomap-rt-server build/tools/loadtest/octomap-rt-loadtest \
#      build/tools/scenegen/octomap-rt-scenegen "$(command -v ip)" .device-bundle/issue25b/bin/
#   ../shared/device/bundle-libs .device-bundle/issue25b .device-bundle/issue25b/bin/*
# The device call: carry [".device-bundle"], command
#   bash docs/bench/gpu/issue25-bound.sh        (timeout 480 s)
# Back here: mkdir -p docs/bench/gpu/issue25-bound && tar -xzf <files_at>/issue25b.tar.gz -C docs/bench/gpu/issue25-bound/
#   docs/bench/dev/issue25-bound/summary.py docs/bench/gpu/issue25-bound
#   docs/bench/dev/issue25-bound/plot.sh docs/bench/gpu/issue25-bound docs/bench/gpu/issue25-bound/bound.png \
#     "skt-corridor, 4 robots x 10 Hz, H200, bound 8MiB (round 1)" -r1
# Shorter calls (a share of one call): SECS=40 ROUNDS=1 (one off and one on round, ~2.5 min);
# OLD=issue25b-old (a second bundle, built like the first from an older commit) adds a round
# "oldon-rK" with the old binary and the bound on after each on round (same call, same load:
# the before/after of a change to the bound).
secs=${SECS:-60}; rounds=${ROUNDS:-2}
. docs/bench/gpu/lib.sh issue25b ${OLD:-}
( while :; do echo "$(date -u +%T) $(cut -d' ' -f1-3 /proc/loadavg) $(nproc)"; sleep 15; done ) > "$O/load.txt" &
load_pid=$!
modes="off on"; [ -n "$OLD" ] && modes="off on oldon"
for round in $(seq 1 "$rounds"); do
  for mode in $modes; do
    left $((470 - secs - 45)) || break 2
    log "bound-$mode-r$round"
    rm -rf "$T/$mode.ot" "$T/$mode.ot".*
    extra=(--map "$T/$mode.ot")
    [ "$mode" != off ] && extra+=(--max-map-memory 8MiB)
    bin=$N/bin; [ "$mode" = oldon ] && bin=$OLD/bin
    r="$mode-r$round"
    timeout $((secs + 40)) "$N/bin/octomap-rt-loadtest" --server "$bin/octomap-rt-server" --producers 4 --rate 10 \
      --duration "$secs" --settle 20 --points 89000 --scene skt-corridor \
      --series "$O/series-$r.csv" --log "$O/server-$r.log" -- -r 0.1 --backend vulkan "${extra[@]}" \
      > "$O/report-$r.txt" 2>&1
    echo "rc=$?" >> "$O/report-$r.txt"
    du -sb "$T/$mode.ot" "$T/$mode.ot.regions" >> "$O/report-$r.txt" 2>&1
  done
done
kill "$load_pid"
exit 0
