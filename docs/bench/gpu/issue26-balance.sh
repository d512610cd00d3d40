#!/bin/bash
# Issue 26 on the GPU machine's cores (CPU only): does the hash rule balance the shards with finer regions?
# One device call (carry .device-bundle/shards-s6 from issue26-balance-bundle.sh; results in $OUT/shards-s6.tar.gz):
#     . docs/bench/gpu/lib.sh shards-s6; . docs/bench/gpu/issue26-balance.sh
# Here (2 cores: N = 1, 2 pinned), after issue26-balance-bundle.sh build:
#     bash -c 'OUT=/tmp/b; mkdir -p $OUT; . docs/bench/gpu/lib.sh shards-s6; . docs/bench/gpu/issue26-balance.sh'
# 1. balance-GRAPH-DEPTH.txt: one process with every shard of N = 1, 2, 4, 8, 16 (unpinned): the busiest
#    shard's voxels against the mean ("voxels max/mean"), merged map = one daemon's, at region depth 10
#    (the old default) and 13 (the new one).
# 2. The set with a core per daemon, at depth 10 and 13 in the same call: for each N <= nproc, N
#    octomap-rt-shard-bench processes side by side, process i pinned to CPU i of the machine's CPUs ordered one
#    thread of every physical core first, then their siblings (so that N <= cores puts no two daemons on one
#    core's hyperthreads; PIN_ORDER=plain: CPU i, as the 16:44 call did; topology.txt records lscpu and the order),
#    and keeping shard i of N only (--only-shard), each decoding every scan, walking every ray and applying its own shard's
#    voxels. The set's octree-stage rate is 1000 / (the slowest shard's update ms a scan); the ratio against
#    N = 1 of the same call and depth is the scaling (goal: >= 0.8 x N). Per process pinned-GRAPH-D-N-i.txt,
#    summary in pinned-summary.txt.
# 3. Routed queries against one daemon (docs/bench/dev/issue26-routed.sh in a network namespace: 3 hashed
#    shards and a whole daemon, CPU back end, 3DTK at 0.1 m; 1000 rounds of 1000 points and 200 rays each),
#    at depth 13 and 10: routed-3dtk_3scans-3-depthD.txt. Each takes ~35 s; started only with 45 s left.
# PINNED_ONLY=1: step 2 alone (~25 s on the H200). Every step is skipped, never cut, past ${BALANCE_UNTIL:-140} s. The graphs travel xz-packed (unpacked here, by
# python3's lzma where there is no xz).
for z in "$N"/data/*/*.graph.xz; do
  [ -e "${z%.xz}" ] || xz -dk "$z" 2> /dev/null ||
    python3 -c 'import lzma, shutil, sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2], "wb"))' "$z" "${z%.xz}"
done
balance() {
  local G=$1 d=$2 g
  g=$(basename "$G" .graph)
  [ -z "${PINNED_ONLY:-}" ] || return 0
  left "${BALANCE_UNTIL:-140}" || return 0
  log "balance $g depth $d"
  timeout 30 "$N/bin/octomap-rt-shard-bench" "$N/data/$G" -r 0.1 --backend cpu-grid --shards 1,2,4,8,16 \
    --depth "$d" > "$O/balance-$g-$d.txt" 2>&1
}
pinned() {
  local G=$1 d=$2 rep=$3 g n i pids base
  g=$(basename "$G" .graph)
  base=0
  for n in 1 2 4 8 16; do
    [ "$n" -le "${#CPUS[@]}" ] || continue
    left "${BALANCE_UNTIL:-140}" || return 0
    log "pinned $g depth $d N=$n"
    pids=()
    for ((i = 0; i < n; i++)); do
      timeout 30 taskset -c "${CPUS[$i]}" "$N/bin/octomap-rt-shard-bench" "$N/data/$G" -r 0.1 --backend cpu-grid \
        --shards "$n" --only-shard "$i" --depth "$d" --repeat "$rep" > "$O/pinned-$g-$d-$n-$i.txt" 2>&1 &
      pids+=($!)
    done
    wait "${pids[@]}"
    # A set's row: shards cut update-max update-mean voxels walk-max walk-mean kept bound merged max/mean.
    awk -v g="$g" -v d="$d" -v n="$n" -v base="$base" '/^every shard:/ {dw0 = $4 + $7; if (dw0 > dw) dw = dw0}
      $1 == n && NF >= 10 && $1 ~ /^[0-9]+$/ {if ($3 > m) m = $3; s += $3; k++}
      END {r = m > 0 ? 1000 / m : 0; b = n == 1 ? 1 : (base > 0 ? r / base : 0)
           printf "%-12s depth %-2d N=%-3d slowest shard update %7.2f ms (mean %7.2f) = octree stage %7.1f scans/s",
                  g, d, n, m, k ? s / k : 0, r
           printf " = %5.2fx N=1 (%4.2f N); decode+walk %6.2f ms a scan (every shard)\n", b, b / n, dw}' \
      "$O"/pinned-"$g"-"$d"-"$n"-*.txt >> "$O/pinned-summary.txt"
    if [ "$n" -eq 1 ]; then
      base=$(awk '$1 == 1 && NF >= 10 && $3 > 0 {printf "%.4f", 1000 / $3}' "$O/pinned-$g-$d-1-0.txt")
    fi
  done
}
# The CPUs this call may use, one thread of every core first (by package and core id), then the second threads, ...
cpus_by_core() {
  local c
  for c in /sys/devices/system/cpu/cpu[0-9]*; do
    taskset -c "${c##*cpu}" true 2> /dev/null || continue
    echo "$(cat "$c/topology/physical_package_id" 2> /dev/null || echo 0) $(cat "$c/topology/core_id" 2> /dev/null ||
      echo "${c##*cpu}") ${c##*cpu}"
  done | sort -k1,1n -k2,2n -k3,3n | awk '{k = $1 " " $2; print r[k]++, $1, $2, $3}' | sort -k1,1n -k2,2n -k3,3n |
    awk '{print $4}'
}
if [ "${PIN_ORDER:-core}" = plain ]; then CPUS=($(seq 0 $(($(nproc) - 1)))); else CPUS=($(cpus_by_core)); fi
{ lscpu; echo "pin order (${PIN_ORDER:-core}): ${CPUS[*]}"; } > "$O/topology.txt" 2>&1
routed() {
  local d=$1 b=$T/build
  [ -z "${PINNED_ONLY:-}" ] || return 0
  left $((${BALANCE_UNTIL:-140} - 45)) || return 0
  log "routed depth $d"
  mkdir -p "$b/server" "$b/client" "$b/tools/shard_bench"
  ln -sf "$N/bin/octomap-rt-server" "$b/server/"
  ln -sf "$N/bin/octomap-rt" "$b/client/"
  ln -sf "$N/bin/octomap-rt-shard-query-bench" "$b/tools/shard_bench/"
  DEPTH=$d SETTLE_S=${SETTLE_S:-6} ROUNDS=${ROUNDS:-1000} ROUTED_OUT=$O/routed timeout 60 docs/bench/dev/issue26-routed.sh "$b" \
    "$N/data/3dtk_dat/3dtk_3scans.graph" 3 > "$O/routed-$d.log" 2>&1
}
balance octomap_share/scan_dat.graph 10
balance octomap_share/scan_dat.graph 13
balance 3dtk_dat/3dtk_3scans.graph 10
balance 3dtk_dat/3dtk_3scans.graph 13
pinned octomap_share/scan_dat.graph 13 "${REPEAT:-10}"
pinned octomap_share/scan_dat.graph 10 "${REPEAT:-10}"
routed 13
routed 10
pinned 3dtk_dat/3dtk_3scans.graph 13 "${REPEAT_3DTK:-4}"
pinned 3dtk_dat/3dtk_3scans.graph 10 "${REPEAT_3DTK:-4}"
