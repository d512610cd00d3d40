"""Where the memory bound's time went: the server's "memory bound costs" status lines
(daemon/map/map_residency.h) added up, for the issue 25 bench scripts (issue25-bound/summary.py,
issue25-soak/figures.py). Most-of fields keep their largest value; the others are summed."""
import re

COST = re.compile(r"memory bound costs: (\d+) passes evicted (\d+) regions in ([0-9.]+) ms \(most ([0-9.]+) ms a "
                  r"pass; walks ([0-9.]+), list ([0-9.]+), encode ([0-9.]+), store write ([0-9.]+), strip "
                  r"([0-9.]+)\); (\d+) restores in ([0-9.]+) ms \(most ([0-9.]+) ms a scan; store read ([0-9.]+), "
                  r"rebuild ([0-9.]+)\)(?:; exact counts recounted (\d+) regions, reused (\d+))?"
                  r"(?:; off stage: sizing ([0-9.]+) ms, waits for the writer ([0-9.]+) ms, (\d+) restores from kept nodes)?"
                  r"(?:; sweeps over the store: (\d+) steps owed, (\d+) regions deleted unread)?")
NAMES = ["passes", "evicted", "evict ms", "most a pass", "walks", "list", "encode", "store write", "strip",
         "restores", "restore ms", "most a scan", "store read", "rebuild", "regions recounted", "reused",
         "sizing (stage 2)", "writer waits", "restores from kept nodes", "steps owed", "deleted unread"]


def bound_costs(lines):
    """The costs over `lines` (a log's lines), in NAMES' order; all zero when none was logged."""
    total = [0.0] * len(NAMES)
    for line in lines:
        m = COST.search(line)
        if m:
            for i, v in enumerate(m.groups()):
                total[i] = max(total[i], float(v or 0)) if NAMES[i].startswith("most") else total[i] + float(v or 0)
    return total


def costs_text(total):
    return ", ".join(f"{n} {v:.0f}" for n, v in zip(NAMES, total))
