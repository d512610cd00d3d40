#!/bin/bash
# campus helper's first device call (issue 12, fourth session): where campus's time goes on the
# H200, ours only (no OctoMap run: `octomap-rt build`, the same engine and two-stage pipeline as
# bench). old = 99c883f (the code measured at 93.7-93.8x), main = a4c5234 (82.4x today), runs
# alternating in one call; first-touch cost of fresh memory (touch probe); the octree stage alone
# on campus's lists, first run (fresh memory) against the best of 3. fb = main with new full blocks
# made as one leaf (server/octree/subtree_update.cpp).
B=$PWD/.device-bundle/campus
. $B/env.sh $B
O=/tmp/campus-out; T=/tmp/campus-tmp; mkdir -p $O $T
start=$SECONDS
log() { echo "== $(date -u +%T) +$((SECONDS - start))s $*" >> $O/progress.txt; }
finish() { log done; uptime >> $O/machine.txt; tar -czf "$OUT/campus-call.tar.gz" -C $O . ; exit 0; }
trap finish EXIT
{ date -u; nproc; nvidia-smi -L; uptime; lscpu | grep 'Model name'; uname -r; free -g;
  cat /sys/kernel/mm/transparent_hugepage/enabled /sys/kernel/mm/transparent_hugepage/defrag; } > $O/machine.txt 2>&1
TV="$B/bin/time -f %e_s_wall_%S_s_sys_%U_s_user_%R_minor_faults_%M_KiB_maxrss"
log touch
for a in ${TOUCH_RUNS:-2048,1,1 2048,15,1 2048,15,1 2048,15,0}; do $B/bin/touch-probe ${a//,/ } >> $O/touch.txt 2>&1; done
log scenegen
$B/bin/octomap-rt-scenegen campus --scan-scale 0.1 ${CAMPUS_POINT_SCALE:+--point-scale $CAMPUS_POINT_SCALE} -o $T/campus.graph > $O/scenegen.txt 2>&1
ln -sf /dev/null $T/null.bt
build() { local tag=$1 bin=$2; shift 2; log build-$tag; echo "### $tag" >> $O/build.txt
  env "$@" $TV timeout 60 $bin build $T/campus.graph -o $T/null.bt -r 0.1 --backend vulkan >> $O/build.txt 2>&1
  echo "rc=$?" >> $O/build.txt; }
build main-a $B/bin/octomap-rt
build old-a $B/bin-old/octomap-rt
build fb-a $B/bin-fb/octomap-rt
build main-b $B/bin/octomap-rt
build old-b $B/bin-old/octomap-rt
build fb-b $B/bin-fb/octomap-rt
build main-nothp $B/bin/octomap-rt MALLOC_CONF=thp:default,metadata_thp:disabled
for v in bin bin-old bin-fb; do log octree-bench-$v; echo "### $v" >> $O/octree-bench.txt
  $TV timeout 60 $B/$v/octomap-rt-octree-bench --data $T --graph campus.graph --backend vulkan --threads 15 \
    --repeat 3 --passes 1 --batched-only >> $O/octree-bench.txt 2>&1
  echo "rc=$?" >> $O/octree-bench.txt; done
exit 0
