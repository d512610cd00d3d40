#!/bin/bash
# Issue 26 on the GPU machine's cores (CPU only), sourced by issue27-distance.sh as its last step
# (after docs/bench/gpu/lib.sh: $N is the bundle with bin/octomap-rt-shard-bench, $O the results).
# The shard set with a core per daemon: for N = 1, 2, 4, 8, 16, N octomap-rt-shard-bench processes
# side by side, process i pinned to core i (taskset) and keeping shard i of N only (--only-shard),
# each decoding every scan, walking every ray and applying its own shard's voxels, one thread a
# stage. The set's octree-stage rate is 1000 / (the slowest shard's update ms a scan); decode +
# walk (every shard's) bound the set's rate whatever N is. Writes pinned-GRAPH-N-i.txt per
# process and pinned-summary.txt. Here (2 cores: N = 1, 2), after issue27-bundle.sh:
#     bash -c 'OUT=/tmp/p; mkdir -p $OUT; . docs/bench/gpu/lib.sh issue27; . docs/bench/gpu/issue26-pinned.sh'
pinned() {
  local G=$1 g n i pids
  g=$(basename "$G" .graph)
  for n in 1 2 4 8 16; do
    [ "$n" -le "$(nproc)" ] || continue
    left "${PINNED_UNTIL:-430}" || return 0
    log "pinned $g N=$n"
    pids=()
    for ((i = 0; i < n; i++)); do
      timeout 40 taskset -c "$i" "$N/bin/octomap-rt-shard-bench" "$N/data/$G" -r 0.1 --backend cpu-grid --shards "$n" \
        --only-shard "$i" --repeat "${REPEAT:-3}" > "$O/pinned-$g-$n-$i.txt" 2>&1 & pids+=($!)
    done
    wait "${pids[@]}"
    awk -v g="$g" -v n="$n" '/^every shard:/ {d = $4; w = $7; if (d + w > dw) dw = d + w}
      $1 == n && NF >= 7 && $1 ~ /^[0-9]+$/ {if ($3 > m) m = $3}
      END {r = 0; if (m > 0) r = 1000 / m
           printf "%-14s N=%-3d slowest shard update %8.2f ms a scan = octree stage %8.1f scans/s;", g, n, m, r
           printf " decode+walk %8.2f ms a scan (every shard)\n", dw}' "$O"/pinned-"$g"-"$n"-*.txt >> "$O/pinned-summary.txt"
  done
}
pinned 3dtk_dat/3dtk_3scans.graph
pinned octomap_share/scan_dat.graph
