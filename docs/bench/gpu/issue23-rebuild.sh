#!/bin/bash
# Issue 23 goal 2 on the H200: the read replica's two rules past its room, one call of <= 300 s (session 11).
# Same map, producers and readers as issue23-clients.sh (9 M-node campus map, 3 producers x 3 Hz at point
# scale 0.25, readers on, 3 query clients, 15 s a run, fresh server each):
#   wait       stage 2 waits for the replica's room (the default)
#   rebuild    --replica-rebuild-slice-nodes 262144: past the room the replica falls behind and rebuilds
#              from the map of record in slices of 262,144 nodes (daemon/map/map_replica.h)
#   rebuild-s  the same with slices of 32,768 nodes (shorter holds of the map of record, more of them)
# Look at, per run: e2e p99, "stage 2 waited ... for room", the fall-behind and rebuild counters of the
# "read replica" line, the replica thread's idle time, and the map of record's lock holders.
# Bundle (dev machine, repository root; the dev preset is RelWithDebInfo):
#   cmake --build build -j2 --target octomap-rt-bigmap-bench
#   rm -rf .device-bundle/replica-rb && mkdir -p .device-bundle/replica-rb/bin
#   cp build/tools/bigmap_bench/octomap-rt-bigmap-bench .device-bundle/replica-rb/bin/
#   strip .device-bundle/replica-rb/bin/*
#   ../shared/device/bundle-libs .device-bundle/replica-rb .device-bundle/replica-rb/bin/*
# There: OUT=$OUT/replica bash docs/bench/gpu/issue23-rebuild.sh, carry [".device-bundle/replica-rb"], 300 s.
. docs/bench/gpu/lib.sh ${BUNDLE:-replica-rb}
B=$N/bin/octomap-rt-bigmap-bench
E=(-r 0.1 --backend ${BACKEND:-vulkan} --preset campus --scan-scale 0.1)
log grow
timeout 25 "$B" grow "${E[@]}" --point-scale 1 --target-nodes ${TARGET_NODES:-9000000} --map "$T/big.ot" \
  > "$O/grow.txt" 2>&1
echo "rc=$?" >> "$O/grow.txt"
R=(--map "$T/big.ot" --stream-point-scale 0.25 --producers 3 --rate 3 --duration 15 --drain-timeout 30
   --readers on --read-replica on --query-clients 3)
END=${END:-285}
run() { local name=$1 cap=$2; shift 2; log "run-$name"; local t=$((END - (SECONDS - start))); [ "$t" -gt "$cap" ] && t=$cap
  timeout "$t" "$B" run "${E[@]}" "${R[@]}" "$@" > "$O/run-$name.txt" 2>&1
  echo "rc=$?" >> "$O/run-$name.txt"; }
left 40 && run wait 80
left 120 && run rebuild 80 --replica-rebuild-slice-nodes 262144
left 200 && run rebuild-s 80 --replica-rebuild-slice-nodes 32768
grep -h '^csv' "$O"/run-*.txt > "$O/runs.csv" 2>/dev/null
exit 0
