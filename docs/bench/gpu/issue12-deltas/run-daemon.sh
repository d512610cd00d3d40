#!/bin/bash
# deltas device run: the daemon with map deltas looked up after each scan (OLD = main f6b0a40)
# against deltas logged by the octree update (NEW = branch perf), same call, same scans:
# skt-corridor --scan-scale 0.2, 3 producers x 100 Hz, as docs/bench/gpu/issue12-daemon-jemalloc/
# run-daemon-x5.sh and run-daemon-x20.sh. Run from the repository root of the carried tree:
#   bash .device-bundle/deltas/run-daemon.sh    (writes $OUT/deltas-daemon.tar.gz)
B=$PWD/.device-bundle/deltas
. $B/env.sh $B
export PATH=$B/bin:$PATH
OLD=$B/bin; NEW=$B/new
O=/tmp/deltas-out; mkdir -p $O
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" | tee -a $O/progress.txt; }
finish() { log done; tar -czf "$OUT/deltas-daemon.tar.gz" -C $O . ; exit 0; }
{ date -u; nproc; nvidia-smi -L; uptime; } > $O/machine.txt 2>&1
SB=$B/server-bench   # the branch's copy: its summary shows the deltas line
log scenegen
SCALE=${DRY:+0.02}; SCALE=${SCALE:-0.2}   # DRY=1: a quick check of the script here (lavapipe)
$NEW/octomap-rt-scenegen skt-corridor --scan-scale $SCALE -o /tmp/skt02.graph > $O/scenegen.txt 2>&1
D="-r 0.1 --backend vulkan"
run() {  # tag build repeat rounds rate [daemon flags...]
  local tag=$1 dir=$2 rep=$3 rounds=$4 rate=$5; shift 5
  log $tag
  [ -n "$DRY" ] && rep=1 rounds=1 rate=5
  OCTOMAP_RT_BUILD_DIR=$dir timeout 60 $SB --graph /tmp/skt02.graph --repeat $rep --rounds $rounds --modes on \
    --rate $rate -- $D "$@" > $O/daemon-$tag.txt 2>&1
}
# every scan in the latency window, the map built during the run
run new-rate100-x5 $NEW 5 2 100
run old-rate100-x5 $OLD 5 2 100
run new-rate100-nodelta-x5 $NEW 5 1 100 --delta-rate 0
# steady state (the last 512 of 1220 scans)
run new-rate100-x20 $NEW 20 1 100
run old-rate100-x20 $OLD 20 1 100
[ $((SECONDS - start)) -lt 150 ] || finish
run new-rate100-exact-x5 $NEW 5 1 100 --delta-exact
[ $((SECONDS - start)) -lt 170 ] || finish
run new-rate200-x20 $NEW 20 1 200
finish
