#!/bin/bash
# deltas device run 2: the steady-state runs again, OLD and NEW alternating twice, with the
# daemons' logs kept (LCM warnings), after NEW lost 15 scans (seq gaps, no kernel drops) in run 1;
# and the new-space runs once more. Same bundle as run-daemon.sh.
B=$PWD/.device-bundle/deltas
. $B/env.sh $B
export PATH=$B/bin:$PATH
OLD=$B/bin; NEW=$B/new
O=/tmp/deltas-out; mkdir -p $O
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" | tee -a $O/progress.txt; }
finish() { log done; tar -czf "$OUT/deltas-daemon-2.tar.gz" -C $O . ; exit 0; }
{ date -u; nproc; nvidia-smi -L; uptime; } > $O/machine.txt 2>&1
SB=$B/server-bench
log scenegen
SCALE=${DRY:+0.02}; SCALE=${SCALE:-0.2}
$NEW/octomap-rt-scenegen skt-corridor --scan-scale $SCALE -o /tmp/skt02.graph > $O/scenegen.txt 2>&1
D="-r 0.1 --backend vulkan"
run() {  # tag build repeat rounds rate [daemon flags...]
  local tag=$1 dir=$2 rep=$3 rounds=$4 rate=$5; shift 5
  log $tag
  [ -n "$DRY" ] && rep=1 rounds=1 rate=5
  mkdir -p $O/logs-$tag
  SERVER_BENCH_KEEP=$O/logs-$tag OCTOMAP_RT_BUILD_DIR=$dir timeout 45 $SB --graph /tmp/skt02.graph --repeat $rep \
    --rounds $rounds --modes on --rate $rate -- $D "$@" > $O/daemon-$tag.txt 2>&1
}
run old-rate100-x20-a $OLD 20 1 100
run new-rate100-x20-a $NEW 20 1 100
run old-rate100-x20-b $OLD 20 1 100
run new-rate100-x20-b $NEW 20 1 100
[ $((SECONDS - start)) -lt 100 ] || finish
run old-rate100-x5-c $OLD 5 1 100
run new-rate100-x5-c $NEW 5 1 100
finish
