#!/bin/bash
# Issue 26 on the GPU machine's cores (CPU only): the shard set with the daemon's ray clip, one
# device call (carry .device-bundle/issue26 from issue26-clip-bundle.sh; results in $OUT/issue26.tar.gz):
#     . docs/bench/gpu/lib.sh issue26; . docs/bench/gpu/issue26-clipped.sh
# Here (2 cores), after issue26-clip-bundle.sh build:
#     bash -c 'OUT=/tmp/c; mkdir -p $OUT; CLIP_SIZES=2; . docs/bench/gpu/lib.sh issue26; . docs/bench/gpu/issue26-clipped.sh'
# For N = 4 and 16 on scan_dat (hash rule at depth 10, and N slabs along x), N octomap-rt-shard-bench
# --clip processes side by side, process i pinned to core i and keeping shard i of N (--only-shard):
# each decodes every scan but walks only the rays that may reach its regions. Then the same N
# without --clip (every shard walks every ray), the before of the same call. Per process
# clipped-RULE-N-i.txt / whole-RULE-N-i.txt; summary.txt: per N the slowest shard's decode + walk
# and update a scan. Every step is skipped, never cut, past 150 s (each N <= 30 s).
clipped() {
  local tag=$1 rule=$2 n=$3 i pids=()
  shift 3
  [ "$n" -le "$(nproc)" ] || return 0
  left "${CLIP_UNTIL:-150}" || return 0
  log "$tag $rule N=$n"
  for ((i = 0; i < n; i++)); do
    timeout 30 taskset -c "$i" "$N/bin/octomap-rt-shard-bench" "$N/data/octomap_share/scan_dat.graph" -r 0.1 \
      --backend cpu-grid --shards "$n" --only-shard "$i" --rule "$rule" --repeat 2 "$@" \
      > "$O/$tag-$rule-$n-$i.txt" 2>&1 & pids+=($!)
  done
  wait "${pids[@]}"
  # Columns of a set's row: shards cut update-max update-mean voxels walk-max walk-mean kept bound.
  awk -v t="$tag" -v r="$rule" -v n="$n" '/^every shard: decode/ {d = $4 + 0; if (d > dm) dm = d}
    $1 == n && NF >= 10 && $1 ~ /^[0-9]+$/ {if ($3 > u) u = $3; if ($6 > w) w = $6; k = k " " $8}
    END {printf "%-8s %-6s N=%-3d slowest: decode %6.2f + walk %8.2f ms, update %8.2f ms a scan; rays kept:%s\n",
         t, r, n, dm, w, u, k}' "$O"/"$tag"-"$rule"-"$n"-*.txt >> "$O/summary.txt"
}
for n in ${CLIP_SIZES:-4 16}; do
  for rule in hash boxes; do
    clipped clipped "$rule" "$n" --clip
    clipped whole "$rule" "$n"
  done
done
