#!/bin/bash
# campus helper's second device call (issue 12, fourth session): `octomap-rt bench` (OctoMap in the
# same process), old = main d054b13, new = main + the full-block shortcut and the uninitialised
# bucket storage (branch perf), alternating: fr079 once each, campus --scan-scale 0.1 new, old, new;
# then ours-only `octomap-rt build` of campus old/new while time is left.
B=$PWD/.device-bundle/campus
. $B/env.sh $B
O=/tmp/campus-out; T=/tmp/campus-tmp; mkdir -p $O $T
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" >> $O/progress.txt; }
finish() { log done; uptime >> $O/machine.txt; tar -czf "$OUT/campus-call2.tar.gz" -C $O . ; exit 0; }
trap finish EXIT
{ date -u; nproc; nvidia-smi -L; uptime; lscpu | grep 'Model name'; uname -r;
  cat /sys/kernel/mm/transparent_hugepage/enabled; } > $O/machine.txt 2>&1
left() { [ $((SECONDS - start)) -lt $1 ]; }
C="--resolutions 0.1 --backends vulkan --traversals octomap --octree batched --warmup 1 --no-octomap-breakdown"
bench() { local name=$1 bin=$2; shift 2; log bench-$name; echo "### $name: $*" >> $O/bench.txt
  timeout ${BENCH_TIMEOUT:-100} $B/$bin/octomap-rt bench $C "$@" --csv $O/$name.csv >> $O/bench.txt 2>&1
  echo "rc=$?" >> $O/bench.txt; }
CAMPUS="--preset campus --scan-scale 0.1 ${CAMPUS_POINT_SCALE:+--point-scale $CAMPUS_POINT_SCALE}"
FR079="--preset fr079 ${FR079_SCALE:+--scan-scale $FR079_SCALE}"
bench fr079-new bin $FR079
bench fr079-old bin-old $FR079
bench campus-new-a bin $CAMPUS
left ${LEFT_OLD:-120} && bench campus-old-a bin-old $CAMPUS
left ${LEFT_NEW:-180} && bench campus-new-b bin $CAMPUS
build() { local tag=$1 bin=$2; log build-$tag; echo "### $tag" >> $O/build.txt
  timeout 30 $B/$bin/octomap-rt build $T/campus.graph -o $T/null.bt -r 0.1 --backend vulkan >> $O/build.txt 2>&1
  echo "rc=$?" >> $O/build.txt; }
if left ${LEFT_BUILD:-205}; then
  log scenegen
  $B/bin/octomap-rt-scenegen campus --scan-scale 0.1 ${CAMPUS_POINT_SCALE:+--point-scale $CAMPUS_POINT_SCALE} \
    -o $T/campus.graph > $O/scenegen.txt 2>&1
  ln -sf /dev/null $T/null.bt
  build new-a bin; left ${LEFT_BUILD2:-215} && build old-a bin-old
fi
exit 0
