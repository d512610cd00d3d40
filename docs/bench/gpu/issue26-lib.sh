#!/bin/bash
# Issue 26's device-call steps as functions, sourced after docs/bench/gpu/lib.sh ($N the bundle with
# bin/octomap-rt-shard-bench and data/, $O the results) by issue26-balance.sh, issue26-pinned.sh and
# issue26-corun.sh. Every step is skipped, never cut, past ${UNTIL_S} seconds of the call.
UNTIL_S=${BALANCE_UNTIL:-${PINNED_UNTIL:-140}}
# The graphs travel xz-packed (unpacked here, by python3's lzma where there is no xz).
for z in "$N"/data/*/*.graph.xz; do
  [ -e "$z" ] || continue
  [ -e "${z%.xz}" ] || xz -dk "$z" 2> /dev/null ||
    python3 -c 'import lzma, shutil, sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2], "wb"))' "$z" "${z%.xz}"
done
# balance GRAPH DEPTH: one process with every shard of N = 1, 2, 4, 8, 16 (no co-run): the busiest shard's voxels
# and update time against the mean, the merged map = one daemon's.
balance() {
  local G=$1 d=$2 g
  g=$(basename "$G" .graph)
  left "$UNTIL_S" || return 0
  log "balance $g depth $d"
  timeout 30 "$N/bin/octomap-rt-shard-bench" "$N/data/$G" -r 0.1 --backend cpu-grid --shards 1,2,4,8,16 \
    --depth "$d" > "$O/balance-$g-$d.txt" 2>&1
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
# pinned GRAPH DEPTH REPEAT: for each N <= the CPUs, N octomap-rt-shard-bench processes side by side, process i
# pinned to CPUS[i] and keeping shard i of N only (--only-shard), each decoding every scan, walking every ray and
# applying its own shard's voxels. The set's octree-stage rate is 1000 / (the slowest shard's update ms a scan);
# its ratio against N = 1 of the same call and depth is the scaling (goal >= 0.8 x N). Per process
# pinned-GRAPH-D-N-i.txt (its stage times: decode, walk, cut, update), one row per N in pinned-summary.txt.
pinned() {
  local G=$1 d=$2 rep=$3 g n i pids base=0
  g=$(basename "$G" .graph)
  for n in 1 2 4 8 16; do
    [ "$n" -le "${#CPUS[@]}" ] || continue
    left "$UNTIL_S" || return 0
    log "pinned $g depth $d N=$n"
    pids=()
    for ((i = 0; i < n; i++)); do
      timeout 40 taskset -c "${CPUS[$i]}" "$N/bin/octomap-rt-shard-bench" "$N/data/$G" -r 0.1 --backend cpu-grid \
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
# routed DEPTH: routed queries against one daemon (docs/bench/dev/issue26-routed.sh in a network namespace: 3 hashed
# shards and a whole daemon, CPU back end, 3DTK at 0.1 m; ROUNDS rounds of 1000 points and 200 rays each):
# routed-3dtk_3scans-3-depthD.txt. Takes ~35 s; started only with 45 s left.
routed() {
  local d=$1 b=$T/build
  left $((UNTIL_S - 45)) || return 0
  log "routed depth $d"
  mkdir -p "$b/server" "$b/client" "$b/tools/shard_bench"
  ln -sf "$N/bin/octomap-rt-server" "$b/server/"
  ln -sf "$N/bin/octomap-rt" "$b/client/"
  ln -sf "$N/bin/octomap-rt-shard-query-bench" "$b/tools/shard_bench/"
  DEPTH=$d SETTLE_S=${SETTLE_S:-6} ROUNDS=${ROUNDS:-1000} ROUTED_OUT=$O/routed timeout 60 docs/bench/dev/issue26-routed.sh "$b" \
    "$N/data/3dtk_dat/3dtk_3scans.graph" 3 > "$O/routed-$d.log" 2>&1
}
