#!/usr/bin/env python3
"""The memory bound benchmark's summary: per run (series-MODE[-rK].csv in OUT_DIR; MODE off or on,
K the round when run.sh alternated rounds), the status windows' end-to-end and octree p99 over the
run's second half (median and max), the tree memory's and RSS's most over it, the bound, and the
evictions and restores at the end; then the ratio of the bounded runs' p99 to the unbounded ones'
(medians over the rounds), and where the bound's time went (the server's "memory bound costs"
lines in server-on[-rK].log, summed over the run). MODE oldon: the bound on with an older binary.
    summary.py OUT_DIR"""
import csv
import re
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from bound_costs import bound_costs, costs_text  # noqa: E402 (docs/bench/dev/bound_costs.py)

out = Path(sys.argv[1])
print("run      e2e p99 ms (median, max)  octree p99 ms (median, max)  tree MiB max  RSS MiB max  bound MiB"
      "  evictions  restores")
per_mode = {"off": [], "on": [], "oldon": []}
for path in sorted(out.glob("series-*.csv")):
    m = re.fullmatch(r"series-(off|on|oldon)(-r\d+)?\.csv", path.name)
    if not m:
        continue
    mode, mode_run = m.group(1), m.group(1) + (m.group(2) or "")
    rows = list(csv.DictReader(path.open()))
    if not rows:
        continue
    last = float(rows[-1]["t_s"])
    half = [r for r in rows if float(r["t_s"]) >= last / 2]
    e2e = [float(r["e2e_p99_ms"]) for r in half]
    octree = [float(r["octree_p99_ms"]) for r in half]
    tree = max(float(r["map_memory_mib"]) for r in half)
    rss = max(float(r["rss_mib"]) for r in half)
    per_mode[mode].append((statistics.median(e2e), statistics.median(octree)))
    print(f"{mode_run:8} {statistics.median(e2e):10.1f} {max(e2e):8.1f} {statistics.median(octree):14.1f} "
          f"{max(octree):8.1f} {tree:16.2f} {rss:11.1f} {float(rows[-1]['bound_mib']):10.1f} "
          f"{rows[-1]['region_evictions']:>10} {rows[-1]['region_restores']:>9}")
for bounded in ("on", "oldon"):  # oldon: the bound on with an older binary (OLD bundle or build)
    if not (per_mode["off"] and per_mode[bounded]):
        continue
    off_e2e = statistics.median(r[0] for r in per_mode["off"])
    on_e2e = statistics.median(r[0] for r in per_mode[bounded])
    off_oct = statistics.median(r[1] for r in per_mode["off"])
    on_oct = statistics.median(r[1] for r in per_mode[bounded])
    print(f"{bounded} / off (medians over {len(per_mode[bounded])} and {len(per_mode['off'])} runs): e2e p99 "
          f"{on_e2e:.1f} / {off_e2e:.1f} = {on_e2e / off_e2e:.2f}x, octree p99 {on_oct:.1f} / {off_oct:.1f} = "
          f"{on_oct / off_oct:.2f}x")
for path in sorted(list(out.glob("server-on*.log")) + list(out.glob("server-oldon*.log"))):
    total = bound_costs(path.open(errors="replace"))
    if any(total):
        print(f"{path.name}: " + costs_text(total))
