#!/bin/bash
# Issue 26: what slows the pinned shard set past N = 4-8 on the GPU machine's cores (CPU only; the shard bench has
# no LCM and no GPU queue, so neither is in it). One device call, ~100 s (carry .device-bundle/shards-s7 from
# issue26-corun-bundle.sh; results in $OUT/shards-s7.tar.gz):
#     . docs/bench/gpu/lib.sh shards-s7; . docs/bench/gpu/issue26-corun.sh
# Here (2 cores: N = 1, 2), after issue26-corun-bundle.sh build:
#     bash -c 'OUT=/tmp/c; mkdir -p $OUT; . docs/bench/gpu/lib.sh shards-s7; . docs/bench/gpu/issue26-corun.sh'
# For N = 1, 2, 4, 8, 16 processes pinned one a core (issue26-lib.sh's CPUS), side by side, each doing the SAME work
# at every N (so any rise with N is the co-run, not the split):
# 1. probe-compute: an awk loop (a few registers, no memory traffic): rises only if the cores themselves slow
#    (clock, the host's neighbours; steal time is in corun-summary.txt from /proc/stat around each N).
# 2. probe-memory: dd from /dev/zero through a 64 MiB buffer (past any L3): the per-process GB/s falls as the
#    processes share the memory bandwidth.
# 3. The pinned set on 3dtk at depth 13 with 12 passes (REPEAT_3DTK; longer than session 6's 4, so the N processes
#    overlap for most of their run) and on scan_dat with 30 (REPEAT): every process's stage times
#    (decode, walk, cut, update) are in pinned-*.txt, the rows in pinned-summary.txt; corun-stages.txt puts each
#    N's mean decode + walk (the same work at every N) beside N = 1's.
# 4. balance on both graphs at depth 13: the same split in one process (no co-run), whose update max/mean against
#    the pinned set's separates the split's own limits (the busiest shard, a fixed cost a shard a scan) from the co-run.
# Every step is skipped, never cut, past ${BALANCE_UNTIL:-120} s.
BALANCE_UNTIL=${BALANCE_UNTIL:-120}
. docs/bench/gpu/issue26-lib.sh
steal() { awk '/^cpu / {print $9}' /proc/stat; }
# probe KIND: N processes pinned side by side; each one's seconds (compute) or GB/s (memory) in probe-KIND-N.txt.
probe() {
  local kind=$1 n i pids s0
  for n in 1 2 4 8 16; do
    [ "$n" -le "${#CPUS[@]}" ] || continue
    left "$BALANCE_UNTIL" || return 0
    log "probe $kind N=$n"
    pids=(); s0=$(steal)
    for ((i = 0; i < n; i++)); do
      if [ "$kind" = compute ]; then
        taskset -c "${CPUS[$i]}" bash -c 's=$EPOCHREALTIME; awk "BEGIN {for (i = 0; i < 3e7; i++) s += i * i}";
          e=$EPOCHREALTIME; echo "$s $e" | awk "{printf \"%.3f\n\", \$2 - \$1}"' > "$T/probe-$kind-$n-$i" 2>&1 &
      else
        taskset -c "${CPUS[$i]}" dd if=/dev/zero of=/dev/null bs=64M count=60 2>&1 |
          awk '/copied/ {print $(NF - 1), $NF}' > "$T/probe-$kind-$n-$i" &
      fi
      pids+=($!)
    done
    wait "${pids[@]}"
    cat "$T"/probe-"$kind"-"$n"-* > "$O/probe-$kind-$n.txt"
    awk -v k="$kind" -v n="$n" -v st=$(($(steal) - s0)) '{v = $1; if ($2 == "MB/s") v /= 1000; s += v; c++;
        if (c == 1 || v > mx) mx = v; if (c == 1 || v < mn) mn = v}
      END {printf "probe %-8s N=%-3d per process mean %8.3f min %8.3f max %8.3f %s; steal %d ticks\n",
           k, n, s / c, mn, mx, k == "compute" ? "s" : "GB/s", st}' "$O/probe-$kind-$n.txt" >> "$O/corun-summary.txt"
  done
}
# stages GRAPH DEPTH: each N's mean decode + walk over its processes against N = 1's (the same work at every N).
stages() {
  local g=$1 d=$2
  for f in "$O"/pinned-"$g"-"$d"-*-*.txt; do
    [ -e "$f" ] && awk -v f="$(basename "$f" .txt)" '/^every shard:/ {print f, $4, $7}' "$f"
  done | awk -v g="$g" -v d="$d" '{split($1, a, "-"); n = a[4]; s[n] += $2 + $3; c[n]++}
    END {for (n = 1; n <= 16; n *= 2) if (c[n]) printf "%-12s depth %d N=%-3d mean decode+walk %7.2f ms a scan = %5.2fx N=1\n",
         g, d, n, s[n] / c[n], (s[n] / c[n]) / (s[1] / c[1])}' >> "$O/corun-stages.txt"
}
probe compute
probe memory
pinned 3dtk_dat/3dtk_3scans.graph 13 "${REPEAT_3DTK:-12}"
stages 3dtk_3scans 13
pinned octomap_share/scan_dat.graph 13 "${REPEAT:-30}"
stages scan_dat 13
balance 3dtk_dat/3dtk_3scans.graph 13
balance octomap_share/scan_dat.graph 13
