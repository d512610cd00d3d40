"""The path search of planner.py: A* over the free cells of a 2D occupancy grid (8-connected,
no corner cutting), with obstacles grown by the robot's radius. numpy only.

Cells are indexed as the grid is: cells[j, i], cell (i, j) centred at
origin + ((i + 0.5) * size, (j + 0.5) * size)."""

import heapq
import math
from typing import List, Optional, Tuple

import numpy as np

Cell = Tuple[int, int]  # (i, j): column, row


def grown(mask: np.ndarray, radius_cells: int) -> np.ndarray:
    """`mask` dilated by a disc of `radius_cells` cells (cells within that distance of a set cell)."""
    out = mask.copy()
    h, w = mask.shape
    for dj in range(-radius_cells, radius_cells + 1):
        for di in range(-radius_cells, radius_cells + 1):
            if (di or dj) and di * di + dj * dj <= radius_cells * radius_cells:
                src = mask[max(0, -dj):h - max(0, dj), max(0, -di):w - max(0, di)]
                out[max(0, dj):h - max(0, -dj), max(0, di):w - max(0, -di)] |= src
    return out


def passable(cells: np.ndarray, free_value: int, occupied_value: int, radius_cells: int) -> np.ndarray:
    """Free cells farther than `radius_cells` from every occupied cell."""
    return (cells == free_value) & ~grown(cells == occupied_value, radius_cells)


def cell_of(xy, origin, size: float) -> Cell:
    return int(math.floor((xy[0] - origin[0]) / size)), int(math.floor((xy[1] - origin[1]) / size))


def centre_of(cell: Cell, origin, size: float) -> Tuple[float, float]:
    return origin[0] + (cell[0] + 0.5) * size, origin[1] + (cell[1] + 0.5) * size


def astar(ok: np.ndarray, start: Cell, goal: Cell) -> Optional[List[Cell]]:
    """The shortest 8-connected path of passable cells from `start` to `goal` (both included),
    or None when there is none (or either end is not passable)."""
    h, w = ok.shape

    def inside_ok(i: int, j: int) -> bool:
        return 0 <= i < w and 0 <= j < h and bool(ok[j, i])

    if not inside_ok(*start) or not inside_ok(*goal):
        return None
    cost = {start: 0.0}
    parent = {start: start}
    open_heap = [(math.dist(start, goal), start)]
    done = set()
    while open_heap:
        _, cur = heapq.heappop(open_heap)
        if cur == goal:
            path = [cur]
            while path[-1] != start:
                path.append(parent[path[-1]])
            return path[::-1]
        if cur in done:
            continue
        done.add(cur)
        ci, cj = cur
        for dj in (-1, 0, 1):
            for di in (-1, 0, 1):
                nxt = (ci + di, cj + dj)
                if (not di and not dj) or not inside_ok(*nxt):
                    continue
                if di and dj and not (inside_ok(ci + di, cj) and inside_ok(ci, cj + dj)):
                    continue  # a diagonal step needs both side cells passable
                c = cost[cur] + math.hypot(di, dj)
                if c < cost.get(nxt, math.inf):
                    cost[nxt] = c
                    parent[nxt] = cur
                    heapq.heappush(open_heap, (c + math.dist(nxt, goal), nxt))
    return None
