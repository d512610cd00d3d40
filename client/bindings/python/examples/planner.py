#!/usr/bin/env python3
"""A planner on octomap-rt-server's map, with Debian's python3 and python3-numpy only: the 2D
grid of the robot's height band, a path over its free cells (A*, obstacles grown by the
robot's radius) whose every waypoint the server confirms free by a point query (cells it
does not are avoided and the path planned again), and what a fan of rays from the robot sees.

    PYTHONPATH=build/python python3 client/bindings/python/examples/planner.py \
        --lcm-url 'udpm://239.255.76.67:7667?ttl=0' --from 1.0,1.5 --to 5.5,1.4 --band 0.3:1.5
"""

import argparse
import json
import math
import sys

import numpy as np

import octomap_rt
from grid_path import astar, cell_of, centre_of, passable

NAMES = {octomap_rt.UNKNOWN: "unknown", octomap_rt.FREE: "free", octomap_rt.OCCUPIED: "occupied"}


class NoPath(RuntimeError):
    """No path between the two points (the message says why)."""


def parse_values(text: str, n: int):
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != n:
        raise argparse.ArgumentTypeError(f"expected {n} comma-separated numbers, got {text!r}")
    return np.array(values)


def parse_point(text: str):
    return parse_values(text, 3)


def parse_xy(text: str):
    return parse_values(text, 2)


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


def plan_path(client, cells, origin, size, start_xy, goal_xy, height, radius, max_replans=50):
    """(waypoints (N, 3), their occupancy probabilities, replans): a grid path from `start_xy`
    to `goal_xy` at `height` whose every waypoint a point query finds free."""
    ok = passable(cells, octomap_rt.FREE, octomap_rt.OCCUPIED, int(math.ceil(radius / size - 1e-9)))
    start, goal = cell_of(start_xy, origin, size), cell_of(goal_xy, origin, size)
    for replans in range(max_replans + 1):
        path = astar(ok, start, goal)
        if path is None:
            ends = [f"{name} cell {c} is {'passable' if astar(ok, c, c) else 'not free (or too near an obstacle)'}"
                    for name, c in (("start", start), ("goal", goal))]
            raise NoPath(f"no path over free cells ({'; '.join(ends)})")
        waypoints = np.array([(*centre_of(c, origin, size), height) for c in path])
        occupancy, probability = client.query_points(waypoints)
        bad = occupancy != octomap_rt.FREE
        if not bad.any():
            return waypoints, probability, replans
        for c in np.array(path)[bad]:
            ok[c[1], c[0]] = False  # not free at the robot's height: avoided from now on
    raise NoPath(f"still not free at {height:g} m after {max_replans} replans")


def fan_of_rays(client, at, rays: int, max_range: float):
    """The nearest obstacle in a horizontal fan of rays from `at`: (hits, rays, distance, heading) or None."""
    angles = np.linspace(0, 2 * np.pi, rays, endpoint=False)
    dirs = np.column_stack([np.cos(angles), np.sin(angles), np.zeros_like(angles)])
    hit, _, ends = client.cast_rays(at, dirs, max_range=max_range, ignore_unknown=True)
    dist = np.linalg.norm(ends - at, axis=1)
    if not hit.any():
        return int(hit.sum()), len(hit), None, None
    k = int(np.argmin(np.where(hit, dist, np.inf)))
    return int(hit.sum()), len(hit), float(dist[k]), float(math.degrees(angles[k]))


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--lcm-url", default=None, help="LCM URL (default: $LCM_DEFAULT_URL, else host-local udpm)")
    p.add_argument("--band", default="0.1:1.8", help="height band Z_MIN:Z_MAX of the robot [m]")
    p.add_argument("--at", type=parse_point, default=np.array([2.0, 2.0, 1.0]), help="robot position X,Y,Z [m] (rays)")
    p.add_argument("--from", dest="start", type=parse_xy, default=None, help="path start X,Y [m] (default: --at)")
    p.add_argument("--to", type=parse_xy, default=None, help="path goal X,Y [m] (no path without it)")
    p.add_argument("--height", type=float, default=None, help="height of the waypoints [m] (default: middle of --band)")
    p.add_argument("--radius", type=float, default=0.0, help="robot radius: cells this near an occupied one are avoided [m]")
    p.add_argument("--cell", type=float, default=0.0, help="grid cell size [m] (0: the map's resolution)")
    p.add_argument("--rays", type=int, default=36, help="rays in the horizontal fan")
    p.add_argument("--range", type=float, default=8.0, help="ray length [m]")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    args = p.parse_args()
    z_min, z_max = (float(v) for v in args.band.split(":"))
    height = (z_min + z_max) / 2 if args.height is None else args.height
    out = {}

    with octomap_rt.MapClient(args.lcm_url) as client:
        status = client.status(timeout_s=10)
        out["server"] = {"server_id": status.server_id, "scans_applied": status.scans_applied,
                         "num_nodes": status.num_nodes}
        cells, (ox, oy), size = client.grid(z_min, z_max, args.cell)
        counts = {name: int((cells == v).sum()) for v, name in NAMES.items()}
        out["grid"] = {"width": cells.shape[1], "height": cells.shape[0], "cell_size": size, "origin": [ox, oy],
                       "band": [z_min, z_max], "cells": counts}
        if not args.json:
            print(f"server {status.server_id}: {status.scans_applied} scans applied, {status.num_nodes} nodes")
            print(f"grid {cells.shape[1]} x {cells.shape[0]} cells of {size:g} m at ({ox:g}, {oy:g}), "
                  f"band {z_min:g}..{z_max:g} m: {counts}")
            print(preview(cells))

        code = 0
        if args.to is not None:
            start = args.at[:2] if args.start is None else args.start
            try:
                waypoints, probability, replans = plan_path(client, cells, (ox, oy), size, start, args.to, height,
                                                            args.radius)
                length = float(np.linalg.norm(np.diff(waypoints, axis=0), axis=1).sum())
                out["path"] = {"waypoints": waypoints.round(4).tolist(), "probability": probability.round(4).tolist(),
                               "length_m": round(length, 3), "replans": replans}
                if not args.json:
                    print(f"path from ({start[0]:g}, {start[1]:g}) to ({args.to[0]:g}, {args.to[1]:g}) at "
                          f"{height:g} m: {len(waypoints)} waypoints, {length:.2f} m, every one free in a point "
                          f"query ({replans} replans)")
                    for w, pr in zip(waypoints, probability):
                        print(f"  waypoint ({w[0]:6.2f}, {w[1]:6.2f}, {w[2]:4.2f}): free p={pr:.2f}")
            except NoPath as e:
                out["path"] = {"error": str(e)}
                code = 1
                print(f"planner: {e}", file=sys.stderr)

        hits, n, dist, heading = fan_of_rays(client, args.at, args.rays, args.range)
        out["rays"] = {"from": args.at.tolist(), "hits": hits, "rays": n, "nearest_m": dist, "heading_deg": heading}
        if not args.json:
            print(f"rays from {tuple(np.round(args.at, 2))}: {hits} of {n} hit within {args.range:g} m")
            if dist is not None:
                print(f"nearest obstacle {dist:.2f} m away, heading {heading:.0f} deg")
    if args.json:
        print(json.dumps(out))
    return code


if __name__ == "__main__":
    sys.exit(main())
