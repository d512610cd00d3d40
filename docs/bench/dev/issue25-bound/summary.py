#!/usr/bin/env python3
"""The memory bound benchmark's summary: per run (series-off.csv, series-on.csv in OUT_DIR), the
status windows' end-to-end and octree p99 over the run's second half (median and max), the tree
memory's and RSS's most over it, the bound, and the evictions and restores at the end.
    summary.py OUT_DIR"""
import csv
import statistics
import sys
from pathlib import Path

out = Path(sys.argv[1])
print("run  e2e p99 ms (median, max)  octree p99 ms (median, max)  tree MiB max  RSS MiB max  bound MiB"
      "  evictions  restores")
for mode in ("off", "on"):
    path = out / f"series-{mode}.csv"
    if not path.exists():
        continue
    rows = list(csv.DictReader(path.open()))
    if not rows:
        continue
    last = float(rows[-1]["t_s"])
    half = [r for r in rows if float(r["t_s"]) >= last / 2]
    e2e = [float(r["e2e_p99_ms"]) for r in half]
    octree = [float(r["octree_p99_ms"]) for r in half]
    tree = max(float(r["map_memory_mib"]) for r in half)
    rss = max(float(r["rss_mib"]) for r in half)
    print(f"{mode:4} {statistics.median(e2e):10.1f} {max(e2e):8.1f} {statistics.median(octree):14.1f} "
          f"{max(octree):8.1f} {tree:16.2f} {rss:11.1f} {float(rows[-1]['bound_mib']):10.1f} "
          f"{rows[-1]['region_evictions']:>10} {rows[-1]['region_restores']:>9}")
