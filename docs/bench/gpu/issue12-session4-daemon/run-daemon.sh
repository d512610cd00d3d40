#!/bin/bash
# The daemon goal on the GPU machine (issue 12, fourth session): main a4c5234 (OLD, the lead's
# bundle of the session's first call) against branch pipebench (NEW: the start-up warm-up and
# the summary's slowest scans), alternating, each on a fresh daemon process, on the same scans
# (skt-corridor --scan-scale 0.2, 3 producers x 100 Hz): --repeat 5 (maps new space) three
# times each, and VARIANTS of NEW (extra daemon flags) in the same rounds; then --repeat 20
# once each. Bundle: $B/old and $B/new (server, client, scenegen), $B/bin (ip, bc, zstd),
# libraries by ../shared/device/bundle-libs, server-bench beside them.
# Run:  B=.device-bundle/daemon bash docs/bench/gpu/issue12-session4-daemon/run-daemon.sh
# DRY=1 runs it in about a minute here (tiny scans, lavapipe) to check it before a call.
B=$(cd "${B:-.device-bundle/daemon}" && pwd)
. $B/env.sh $B
export PATH=$B/bin:$PATH
O=$(mktemp -d /tmp/daemon-out-XXXXXX); G=$O/skt02.graph
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" | tee -a $O/progress.txt; }
finish() { log done; uptime >> $O/machine.txt; rm -f $G; tar -czf "${OUT:-/tmp}/daemon-call.tar.gz" -C $O . ; rm -rf $O; exit 0; }
trap finish EXIT
{ date -u; nproc; nvidia-smi -L; uptime; lscpu | grep 'Model name'; } > $O/machine.txt 2>&1
SCALE=${DRY:+0.02}; SCALE=${SCALE:-0.2}
LIMIT=${LIMIT:-170}   # seconds: no new run starts after this
log scenegen
$B/new/octomap-rt-scenegen skt-corridor --scan-scale $SCALE -o $G > $O/scenegen.txt 2>&1
run() {  # tag build repeat [extra daemon flags]
  local tag=$1 dir=$2 rep=$3 rate=100; shift 3
  [ $((SECONDS - start)) -lt $LIMIT ] || { log "skip $tag (time)"; return; }
  log $tag
  [ -n "$DRY" ] && rep=1 rate=5
  mkdir -p $O/logs-$tag
  SERVER_BENCH_KEEP=$O/logs-$tag OCTOMAP_RT_BUILD_DIR=$dir timeout 60 $B/server-bench --graph $G --repeat $rep \
    --rounds 1 --modes on --rate $rate -- -r 0.1 --backend vulkan "$@" > $O/daemon-$tag.txt 2>&1
}
IFS=';' read -r -a VARIANTS <<< "${VARIANTS:-}"   # e.g. "t12:--threads 12;nowarm:--warm-up-points 0"
for k in a b c; do
  run old-x5-$k $B/old 5
  run new-x5-$k $B/new 5
  for v in "${VARIANTS[@]}"; do
    [ -n "$v" ] || continue
    read -r -a flags <<< "${v#*:}"
    run new-${v%%:*}-x5-$k $B/new 5 "${flags[@]}"
  done
done
run old-x20 $B/old 20
run new-x20 $B/new 20
