#!/bin/bash
# Issue 26 on the GPU machine's cores (CPU only), sourced by issue27-distance.sh as its last step
# (after docs/bench/gpu/lib.sh: $N is the bundle with bin/octomap-rt-shard-bench, $O the results):
# issue26-lib.sh's pinned set at the default region depth (13) on both graphs, until ${PINNED_UNTIL:-430} s.
# Here (2 cores: N = 1, 2), after issue27-bundle.sh:
#     bash -c 'OUT=/tmp/p; mkdir -p $OUT; . docs/bench/gpu/lib.sh issue27; . docs/bench/gpu/issue26-pinned.sh'
PINNED_UNTIL=${PINNED_UNTIL:-430}
. docs/bench/gpu/issue26-lib.sh
pinned 3dtk_dat/3dtk_3scans.graph 13 "${REPEAT:-3}"
pinned octomap_share/scan_dat.graph 13 "${REPEAT:-3}"
