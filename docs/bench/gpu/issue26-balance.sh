#!/bin/bash
# Issue 26 on the GPU machine's cores (CPU only): does the hash rule balance the shards with finer regions?
# One device call (carry .device-bundle/shards-s6 from `issue26-balance-bundle.sh build shards-s6`; results in $OUT/shards-s6.tar.gz):
#     . docs/bench/gpu/lib.sh shards-s6; . docs/bench/gpu/issue26-balance.sh
# Here (2 cores: N = 1, 2 pinned), after issue26-balance-bundle.sh build:
#     bash -c 'OUT=/tmp/b; mkdir -p $OUT; . docs/bench/gpu/lib.sh shards-s6; . docs/bench/gpu/issue26-balance.sh'
# 1. balance-GRAPH-DEPTH.txt at region depth 10 (the old default) and 13 (the new one).
# 2. The pinned set (issue26-lib.sh's pinned) at depth 10 and 13 in the same call; core-first pinning
#    (PIN_ORDER=plain: CPU i, as the 16:44 call did; topology.txt records lscpu and the order).
# 3. Routed queries against one daemon at depth 13 and 10.
# PINNED_ONLY=1: step 2 alone (~25 s on the H200). Every step is skipped past ${BALANCE_UNTIL:-140} s.
. docs/bench/gpu/issue26-lib.sh
if [ -z "${PINNED_ONLY:-}" ]; then
  balance octomap_share/scan_dat.graph 10
  balance octomap_share/scan_dat.graph 13
  balance 3dtk_dat/3dtk_3scans.graph 10
  balance 3dtk_dat/3dtk_3scans.graph 13
fi
pinned octomap_share/scan_dat.graph 13 "${REPEAT:-10}"
pinned octomap_share/scan_dat.graph 10 "${REPEAT:-10}"
if [ -z "${PINNED_ONLY:-}" ]; then
  routed 13
  routed 10
fi
pinned 3dtk_dat/3dtk_3scans.graph 13 "${REPEAT_3DTK:-4}"
pinned 3dtk_dat/3dtk_3scans.graph 10 "${REPEAT_3DTK:-4}"
