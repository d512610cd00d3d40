#!/usr/bin/env python3
"""The soak's figures (issue 25) from a run's folder: series.csv (every status) and server.log.

    docs/bench/dev/issue25-soak/figures.py RUN_DIR [BOUND_MIB [SKIP_S]]

Prints the server's RSS and map memory per quarter of the run (flat: the last quarters within
+-5 % of the second), how often the map memory was above the bound and above 1.1 x the bound
(BOUND_MIB given), the end-to-end and octree p99 per tenth of the run, and where the bound's
time went (the server's "memory bound costs" lines added up).
"""
import csv
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from bound_costs import bound_costs, costs_text  # noqa: E402 (docs/bench/dev/bound_costs.py)

run = Path(sys.argv[1])
bound = float(sys.argv[2]) if len(sys.argv) > 2 else None
skip = float(sys.argv[3]) if len(sys.argv) > 3 else 60  # seconds left out at the start (the map's build-up)
rows = list(csv.DictReader((run / "series.csv").open()))
t = [float(r["t_s"]) for r in rows]
end = t[-1]


def col(name):
    return [float(r[name]) for r in rows]


def between(a, b, xs):
    return [x for tt, x in zip(t, xs) if a <= tt < b]


for name, xs in (("server RSS", col("rss_mib")), ("map memory", col("map_memory_mib"))):
    quarters = [statistics.mean(between(end * i / 4, end * (i + 1) / 4 + 1, xs)) for i in range(4)]
    print(f"{name} MiB, mean per quarter: " + ", ".join(f"{q:.2f}" for q in quarters) +
          f"; 4th vs 2nd quarter {100 * (quarters[3] / quarters[1] - 1):+.1f} %, "
          f"4th vs 1st {100 * (quarters[3] / quarters[0] - 1):+.1f} %")
if bound:
    after = between(skip, end + 1, col("map_memory_mib"))
    print(f"map memory after the first {skip:.0f} s: median {statistics.median(after):.2f} MiB, max {max(after):.2f}; "
          f"above the bound {sum(m > bound for m in after)} of {len(after)} statuses, "
          f"above 1.1 x the bound {sum(m > 1.1 * bound for m in after)}")
for i in range(10):
    a, b = end * i / 10, end * (i + 1) / 10 + 1
    e2e, octree = between(a, b, col("e2e_p99_ms")), between(a, b, col("octree_p99_ms")) if "octree_p99_ms" in rows[0] else []
    print(f"{a / 60:5.1f}-{b / 60:4.1f} min: e2e p99 median {statistics.median(e2e):.0f} ms" +
          (f", octree p99 median {statistics.median(octree):.0f} ms" if octree else ""))
print("last status:", rows[-1])
log = run / "server.log"
total = bound_costs(log.open(errors="replace")) if log.exists() else []
if any(total):
    print("the bound's costs (ms, summed): " + costs_text(total))
