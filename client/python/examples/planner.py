#!/usr/bin/env python3
"""A planner's look at octomap-rt-server's map, with Debian's python3 and python3-numpy only:
the 2D grid of the robot's height band, free waypoints on it confirmed by point queries, and
what a fan of rays from the robot sees.

    PYTHONPATH=build/python python3 client/python/examples/planner.py \
        --lcm-url 'udpm://239.255.76.67:7667?ttl=0' --at 2,2,1
"""

import argparse
import math
import sys

import numpy as np

import octomap_rt


def parse_point(text: str):
    values = [float(v) for v in text.split(",")]
    if len(values) != 3:
        raise argparse.ArgumentTypeError(f"expected X,Y,Z, got {text!r}")
    return np.array(values)


def preview(cells, width=72):
    """The grid as text, north up: '#' occupied, '.' free, ' ' unknown."""
    step = max(1, math.ceil(cells.shape[1] / width))
    rows = []
    for j in range(cells.shape[0] - 1, -1, -2 * step):  # two grid rows a text line: cells are square
        block = cells[max(0, j - step + 1):j + 1]
        line = ""
        for i in range(0, cells.shape[1], step):
            c = block[:, i:i + step]
            line += "#" if (c == octomap_rt.OCCUPIED).any() else "." if (c == octomap_rt.FREE).any() else " "
        rows.append(line.rstrip())
    return "\n".join(rows)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--lcm-url", default=None, help="LCM URL (default: $LCM_DEFAULT_URL, else host-local udpm)")
    p.add_argument("--band", default="0.1:1.8", help="height band Z_MIN:Z_MAX of the robot [m]")
    p.add_argument("--at", type=parse_point, default=np.array([2.0, 2.0, 1.0]), help="robot position X,Y,Z [m]")
    p.add_argument("--waypoints", type=int, default=8, help="free waypoints to pick and check")
    p.add_argument("--rays", type=int, default=36, help="rays in the horizontal fan")
    p.add_argument("--range", type=float, default=8.0, help="ray length [m]")
    args = p.parse_args()
    z_min, z_max = (float(v) for v in args.band.split(":"))

    with octomap_rt.MapClient(args.lcm_url) as client:
        status = client.status(timeout_s=10)
        print(f"server {status.server_id}: {status.scans_applied} scans applied, {status.num_nodes} nodes")

        cells, (ox, oy), size = client.grid(z_min, z_max)
        counts = {name: int((cells == v).sum()) for name, v in
                  (("occupied", octomap_rt.OCCUPIED), ("free", octomap_rt.FREE), ("unknown", octomap_rt.UNKNOWN))}
        print(f"grid {cells.shape[1]} x {cells.shape[0]} cells of {size:g} m at ({ox:g}, {oy:g}), "
              f"band {z_min:g}..{z_max:g} m: {counts}")
        print(preview(cells))

        # Waypoints: free cells spread over the grid, checked by the server at the robot's height.
        free_cells = np.argwhere(cells == octomap_rt.FREE)
        if len(free_cells) == 0:
            print("no free cells in the band: nothing to plan on")
            return 1
        pick = free_cells[np.linspace(0, len(free_cells) - 1, args.waypoints).astype(int)]
        waypoints = np.column_stack([ox + (pick[:, 1] + 0.5) * size, oy + (pick[:, 0] + 0.5) * size,
                                     np.full(len(pick), (z_min + z_max) / 2)])
        occupancy, probability = client.query_points(waypoints)
        names = {octomap_rt.UNKNOWN: "unknown", octomap_rt.FREE: "free", octomap_rt.OCCUPIED: "occupied"}
        for w, o, pr in zip(waypoints, occupancy, probability):
            print(f"waypoint ({w[0]:6.2f}, {w[1]:6.2f}, {w[2]:4.2f}): {names[int(o)]:8s} p={pr:.2f}")

        # A horizontal fan of rays from the robot: the nearest obstacle around it.
        angles = np.linspace(0, 2 * np.pi, args.rays, endpoint=False)
        dirs = np.column_stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)])
        hit, _, ends = client.cast_rays(args.at, dirs, max_range=args.range, ignore_unknown=True)
        dist = np.linalg.norm(ends - args.at, axis=1)
        print(f"rays from {tuple(np.round(args.at, 2))}: {int(hit.sum())} of {len(hit)} hit within {args.range:g} m")
        if hit.any():
            k = int(np.argmin(np.where(hit, dist, np.inf)))
            print(f"nearest obstacle {dist[k]:.2f} m away, heading {math.degrees(angles[k]):.0f} deg")
    return 0


if __name__ == "__main__":
    sys.exit(main())
