#!/bin/bash
# Issue 25's soak on the GPU machine, one device call of at most 8 minutes: 4 robots x 10 Hz
# circling the fr079-real preset (OctoMap's real FR-079 map seen by a simulated LiDAR, full
# 89k-point scans) for 7 minutes against octomap-rt-server on the vulkan back end with decay
# and clearing on; the server's RSS, map memory and end-to-end p99 at every status (0.5 s).
#
# Here, first (from the repository root, after building the three targets):
#   cmake --build build --target octomap-rt-server octomap-rt-loadtest octomap-rt-scenegen
#   mkdir -p .device-bundle/issue25/bin .device-data/octomap_share
#   cp build/server/octomap-rt-server build/tools/loadtest/octomap-rt-loadtest \
#      build/tools/scenegen/octomap-rt-scenegen "$(command -v ip)" .device-bundle/issue25/bin/
#   ../shared/device/bundle-libs .device-bundle/issue25 .device-bundle/issue25/bin/*
#   cp ../shared/data/octomap_share/geb079.bt .device-data/octomap_share/
# The device call: carry [".device-bundle", ".device-data"], command
#   bash docs/bench/gpu/issue25-soak.sh
# Back here: tar -xzf <files_at>/issue25.tar.gz -C docs/bench/gpu/issue25-soak/ and
#   docs/bench/dev/issue25-soak/plot.sh docs/bench/gpu/issue25-soak/series.csv \
#     docs/bench/gpu/issue25-soak/soak.png "fr079-real, 4 robots x 10 Hz, H200"
. docs/bench/gpu/lib.sh issue25
log soak
( while :; do echo "$(date -u +%T) $(cut -d' ' -f1-3 /proc/loadavg) $(nproc)"; sleep 15; done ) > "$O/load.txt" &
load_pid=$!
timeout 370 "$N/bin/octomap-rt-loadtest" --server "$N/bin/octomap-rt-server" --producers 4 --rate 10 \
  --duration 300 --settle 30 --points 89000 --scene fr079-real --data .device-data --series "$O/series.csv" \
  --log "$O/server.log" -- -r 0.1 --backend vulkan --decay-half-life 60 --decay-step 5 \
  --clear-radius 20 --clear-recent 30 --clear-period 10 > "$O/report.txt" 2>&1
echo "rc=$?" >> "$O/report.txt"
kill "$load_pid"
exit 0
