#!/bin/bash
# Issue 26: queries routed across a shard set against one daemon (docs/BENCHMARKS.md, "Shards"),
# from the repository root, with a build tree holding octomap-rt-server, octomap-rt and
# octomap-rt-shard-query-bench:
#     [DEPTH=D] [SETTLE_S=S] [ROUNDS=R] [ROUTED_OUT=DIR] docs/bench/dev/issue26-routed.sh [BUILD] [GRAPH] [SHARDS]
# In a private network namespace (tests/python/run-in-netns): SHARDS daemons (--shard i/N, hash
# rule, region depth D, default the daemon's) in namespace campus and one whole daemon in namespace one, all on
# the CPU back end; the graph's scans replayed once to each namespace; then the bench's R rounds (default 200).
# S seconds (default 20) after the replays for the last scans to be applied everywhere.
# Output: DIR (default docs/bench/dev/issue26-routed)/<graph>-<N>[-depth<D>].txt (and the machine's load before
# and after).
set -euo pipefail
build=${1:-build} graph=${2:-../shared/data/3dtk_dat/3dtk_3scans.graph} n=${3:-3}
if [ "${ORT_IN_NETNS:-}" != 1 ]; then exec tests/python/run-in-netns "$0" "$@"; fi
out=${ROUTED_OUT:-docs/bench/dev/issue26-routed}; mkdir -p "$out"
depth=${DEPTH:-}
res="$out/$(basename "$graph" .graph)-$n${depth:+-depth$depth}.txt"
url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304"
tmp=$(mktemp -d); pids=()
stop() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; wait; rm -rf "$tmp"; }
trap stop EXIT
common=(-r 0.1 --backend cpu --lcm-url "$url" --warm-up-points 0 --query-lock-ms 1000)
for ((i = 0; i < n; i++)); do
  "$build/server/octomap-rt-server" "${common[@]}" --namespace campus --shard "$i/$n" \
    ${depth:+--shard-region-depth "$depth"} > "$tmp/shard$i.log" 2>&1 &
  pids+=($!)
done
"$build/server/octomap-rt-server" "${common[@]}" --namespace one > "$tmp/one.log" 2>&1 & pids+=($!)
sleep 3
for ns in campus one; do
  "$build/client/octomap-rt" replay "$graph" --robot bench --rate 1 --namespace "$ns" --lcm-url "$url" \
    --wait-for-server 30 > "$tmp/replay-$ns.log" 2>&1
done
sleep "${SETTLE_S:-20}"  # the last scans applied everywhere (3dtk: 3 scans, each well under a second a daemon)
{ echo "# $(date -u) $(nproc) cores; load $(cut -d' ' -f1-3 /proc/loadavg)"
  "$build/tools/shard_bench/octomap-rt-shard-query-bench" "$graph" --lcm-url "$url" --shards campus --whole one \
    --rounds "${ROUNDS:-200}"
  echo "# load after: $(cut -d' ' -f1-3 /proc/loadavg)"; } | tee "$res"
