#!/bin/bash
# Issue 25's soak on the GPU machine, one device call of at most 8 minutes: 4 robots x 10 Hz
# circling the fr079-real preset (OctoMap's real FR-079 map seen by a simulated LiDAR, full
# 89k-point scans) for 7 minutes against octomap-rt-server on the vulkan back end with decay,
# clearing and the memory bound on (--max-map-memory $BOUND, default 8MiB, the dev soak's; BOUND=0:
# decay and clearing only, as the 2026-12-01 run); the server's RSS, map memory (as the bound
# counts it), evicted bytes and end-to-end p99 at every status (0.5 s), the bound's cost
# breakdown every 10 s in server.log ("memory bound costs").
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
. docs/bench/gpu/lib.sh issue25
bound=${BOUND:-8MiB}
log "soak bound $bound"
( while :; do echo "$(date -u +%T) $(cut -d' ' -f1-3 /proc/loadavg) $(nproc)"; sleep 15; done ) > "$O/load.txt" &
load_pid=$!
extra=()
[ "$bound" = 0 ] || extra=(--map "$T/soak.ot" --max-map-memory "$bound")
timeout 460 "$N/bin/octomap-rt-loadtest" --server "$N/bin/octomap-rt-server" --producers 4 --rate 10 \
  --duration 420 --settle 30 --points 89000 --scene fr079-real --data .device-data --series "$O/series.csv" \
  --log "$O/server.log" -- -r 0.1 --backend vulkan --decay-half-life 60 --decay-step 5 \
  --clear-radius 20 --clear-recent 30 --clear-period 10 "${extra[@]}" > "$O/report.txt" 2>&1
echo "rc=$?" >> "$O/report.txt"
du -sb "$T"/soak.ot* >> "$O/report.txt" 2>&1
kill "$load_pid"
exit 0
