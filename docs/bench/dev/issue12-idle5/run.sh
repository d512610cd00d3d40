#!/bin/bash
# Lead's idle-machine dev figures on main (run only when no helper/CI runs anything).
set -u
cd /work/wt/lead
O=${1:-/tmp/idle5}; mkdir -p $O
C="--resolutions 0.1 --backends cpu-grid --traversals octomap --octree batched --no-octomap-breakdown"
B=build/client/octomap-rt
for k in a b c d; do uptime >> $O/load.txt; $B bench $C --repeat 3 --preset fr079 --scan-scale 0.1 --csv $O/fr079-$k.csv > $O/fr079-$k.out 2>&1; done
for k in a b c; do uptime >> $O/load.txt; $B bench $C --repeat 3 --preset none --data ../shared/data --csv $O/real-$k.csv > $O/real-$k.out 2>&1; done
for k in a b; do uptime >> $O/load.txt; $B bench $C --repeat 3 --preset skt-corridor --scan-scale 0.1 --csv $O/skt-$k.csv > $O/skt-$k.out 2>&1; done
uptime >> $O/load.txt
for f in $O/*.csv; do /usr/bin/python3 - "$f" <<'PY'
import csv,sys
for r in csv.DictReader(open(sys.argv[1])):
    if r['backend']!='octomap':
        print(f"{sys.argv[1].split('/')[-1]:12s} {r['dataset']:12s} octomap {float(r['octomap_total_ms']):8.1f} ours {float(r['total_ms']):7.1f} x{float(r['speedup']):5.2f} prep {float(r['prepare_ms']):6.1f} shoot {float(r['shoot_ms']):7.1f} compact {float(r['compact_ms']):6.1f} octree {float(r['octree_ms']):6.1f} identical {r['map_identical']}")
PY
done
