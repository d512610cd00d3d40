#!/bin/bash
# The daemon goal on the GPU machine (issue 12): main before this change (OLD) against it (NEW),
# alternating, on the same scans (skt-corridor --scan-scale 0.2, 3 producers x 100 Hz): three
# runs that map new space (--repeat 5) and one steady run (--repeat 20) each, then the intake
# bench (NEW) on the same scans. NEW's summaries carry stage 1's parts and each scan's waits.
# Bundle: docs/bench/gpu/issue12-stage1/make-bundle.sh OLD_BUILD_DIR NEW_BUILD_DIR (here, in the
# checkout the device tool carries; $B/old and $B/new hold each build's server, client and
# scenegen, $B/new also octomap-rt-intake-bench; ip, bc, zstd and the libraries beside them).
# Run:  B=.device-bundle/stage1 bash docs/bench/gpu/issue12-stage1/run-daemon.sh
# DRY=1 runs it in a minute on any machine (tiny scans, lavapipe), to check it before a call.
B=$(cd "${B:-.device-bundle/stage1}" && pwd)
. $B/env.sh $B
export PATH=$B/bin:$PATH
O=$(mktemp -d /tmp/stage1-out-XXXXXX); G=$O/skt02.graph
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" | tee -a $O/progress.txt; }
finish() { log done; uptime >> $O/machine.txt; rm -f $G; tar -czf "${OUT:-/tmp}/stage1-daemon.tar.gz" -C $O . ; rm -rf $O; exit 0; }
trap finish EXIT
{ date -u; nproc; nvidia-smi -L; uptime; } > $O/machine.txt 2>&1
SCALE=${DRY:+0.02}; SCALE=${SCALE:-0.2}
log scenegen
$B/new/octomap-rt-scenegen skt-corridor --scan-scale $SCALE -o $G > $O/scenegen.txt 2>&1
run() {  # tag build repeat
  local tag=$1 dir=$2 rep=$3 rate=100
  log $tag
  [ -n "$DRY" ] && rep=1 rate=5
  OCTOMAP_RT_BUILD_DIR=$dir timeout 60 $B/server-bench --graph $G --repeat $rep --rounds 1 \
    --modes on --rate $rate -- -r 0.1 --backend vulkan > $O/daemon-$tag.txt 2>&1
}
for k in a b c; do
  run old-x5-$k $B/old 5
  run new-x5-$k $B/new 5
done
run old-x20 $B/old 20
run new-x20 $B/new 20
log intake-bench
$B/new/octomap-rt-intake-bench $G --rounds 3 > $O/intake-bench.txt 2> /dev/null
