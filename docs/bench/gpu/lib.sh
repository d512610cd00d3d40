#!/bin/bash
# Set-up shared by the device-call scripts (issue 12, from the fifth session on): source it first thing on the
# GPU machine, from the repository root, as
#     . docs/bench/gpu/lib.sh NAME [OLD_BUNDLE]
# NAME: the bundle .device-bundle/NAME (bin/ with octomap-rt, octomap-rt-server, octomap-rt-scenegen, ip, bc,
# zstd; server-bench beside bin/; libraries by ../shared/device/bundle-libs) and the result, $OUT/NAME.tar.gz.
# OLD_BUNDLE: a second bundle (old binaries) as $OLD. Everything a script writes under $O comes back; the
# machine's description (CPU, GPU, driver, load, steal time) is recorded at the start and the end.
N=$PWD/.device-bundle/$1
OLD=${2:+$PWD/.device-bundle/$2}
. "$N/env.sh" "$N"
export PATH=$N/bin:$PATH
O=/tmp/$1-out; T=/tmp/$1-tmp; mkdir -p "$O" "$T"
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" >> "$O/progress.txt"; }
# True while fewer than $1 seconds of the call have passed: later steps are skipped, not cut off.
left() { [ $((SECONDS - start)) -lt "$1" ]; }
machine() { { date -u; nproc; uptime; head -1 /proc/stat; nvidia-smi -L;
              nvidia-smi --query-gpu=driver_version --format=csv,noheader; lscpu | grep -E 'Model name|Hypervisor';
              cat /sys/kernel/mm/transparent_hugepage/enabled; } >> "$O/machine.txt" 2>&1; }
finish() { log done; machine; tar -czf "$OUT/$(basename "$N").tar.gz" -C "$O" .; exit 0; }
trap finish EXIT
machine
# The options of every bench run of issue 12 on the GPU machine (docs/BENCHMARKS.md).
C="--resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown"
# bench NAME BUNDLE ARGS...: one `octomap-rt bench` process, its CSV as NAME.csv, the CPU counters around it.
bench() { local name=$1 bin=$2; shift 2; log "bench-$name"; echo "### $name: $*" >> "$O/bench.txt"
  echo "before $(head -1 /proc/stat)" >> "$O/bench.txt"
  timeout 150 "$bin/bin/octomap-rt" bench $C "$@" --csv "$O/$name.csv" >> "$O/bench.txt" 2>&1
  echo "rc=$? after $(head -1 /proc/stat)" >> "$O/bench.txt"; }
# daemon TAG BUNDLE REPEAT GRAPH: the daemon goal (3 producers x 100 Hz, pipeline on), a fresh daemon.
daemon() { local tag=$1 bin=$2 rep=$3 graph=$4; log "daemon-$tag"
  OCTOMAP_RT_BUILD_DIR=$bin/bin timeout 60 "$bin/server-bench" --graph "$graph" --repeat "$rep" --rounds 1 \
    --modes on --rate 100 -- -r 0.1 --backend vulkan > "$O/daemon-$tag.txt" 2>&1; }
# loaded NAME BUNDLE ARGS...: bench beside 4 busy shell loops (a synthetic slow machine: 15 octree workers,
# stage 1 and the loops share 16 cores), started before the process and killed by pid after it.
loaded() { local pids=(); for _ in 1 2 3 4; do (while :; do :; done) & pids+=($!); done
  bench "$@"; kill "${pids[@]}"; }
