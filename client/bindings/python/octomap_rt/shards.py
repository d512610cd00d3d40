"""One map from a shard set (docs/PROTOCOL.md, "Shards"): the daemons of one namespace started with
--shard i/N each map the voxels of their own regions. ShardClient finds them by their statuses
(each announces the whole set), routes point, ray, box and grid queries by region, and fetches a
snapshot from every shard and merges them. The merge rules are the C++ shard client's
(client/shard_client/): a point goes to its voxel's shard; box counts add up; a ray is cast on
every shard, each stopping in its own regions only, and the answer is the stop nearest the
origin on the ray's walk (its L1 key distance from the origin's key), the owner's where several
stop at one voxel; a grid cell is the most of the shards' cells (occupied > free > unknown).
A shard that does not answer is named in the answer's `missing` (a partial answer), never left
out silently."""

import math
import time
from dataclasses import dataclass, field
from typing import Dict, Optional

from ._types import map_info_t, server_status_t
from .bt_reader import TREE_DEPTH, BtMap, read_bt
from .channels import Channels, in_namespace, namespace_from
from .map_client import MapClient, ServerTimeout
from .protocol_table import MAX_SHARDS, SHARD_NAMESPACE_PREFIX
from .queries import FREE, OCCUPIED, UNKNOWN, QueryError, Wait
from .snapshot_fetch import FetchError, new_client_id
from .transport import open_transport

_KEY_ORIGIN = 1 << (TREE_DEPTH - 1)
_M32 = 0xFFFFFFFF


def shard_namespace(ns: str, index: int) -> str:
    """The namespace of shard `index`'s own channels (protocol::shard_namespace)."""
    return in_namespace(ns, f"{SHARD_NAMESPACE_PREFIX}{index}")


def region_hash(x: int, y: int, z: int) -> int:
    """protocol/shards/shard_set.cpp's region_hash (fmix32 of the mixed coordinates)."""
    h = ((x * 73856093) & _M32) ^ ((y * 19349663) & _M32) ^ ((z * 83492791) & _M32)
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & _M32
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & _M32
    return h ^ (h >> 16)


class ShardSetError(ValueError):
    """A status whose shard fields are out of range, or two different sets in one namespace."""


@dataclass(frozen=True)
class ShardSet:
    rule: int            # map_info_t.SHARD_RULE_*
    region_depth: int    # 1 .. 16
    count: int           # 1 .. MAX_SHARDS
    boxes: tuple = ()    # SHARD_RULE_BOXES: per shard (min x y z, max x y z), region coordinates, max excluded

    @staticmethod
    def of_status(s) -> "ShardSet":
        """The set a status (or map_info_t) announces, every field range-checked."""
        if not 1 <= s.shard_count <= MAX_SHARDS:
            raise ShardSetError(f"shard count {s.shard_count} is outside 1 .. {MAX_SHARDS}")
        if not 0 <= s.shard_index < s.shard_count:
            raise ShardSetError(f"shard index {s.shard_index} is not below the count {s.shard_count}")
        if not 1 <= s.shard_region_depth <= TREE_DEPTH:
            raise ShardSetError(f"region depth {s.shard_region_depth} is outside 1 .. {TREE_DEPTH}")
        boxes = ()
        if s.shard_rule == map_info_t.SHARD_RULE_BOXES:
            v = list(s.shard_box)
            if len(v) != 6 * s.shard_count:
                raise ShardSetError(f"{len(v)} box values for {s.shard_count} shards (6 a shard)")
            boxes = tuple(tuple(v[6 * i:6 * i + 6]) for i in range(s.shard_count))
        elif s.shard_rule == map_info_t.SHARD_RULE_WHOLE:
            if s.shard_count != 1:
                raise ShardSetError("a set of several shards needs a rule")
        elif s.shard_rule != map_info_t.SHARD_RULE_HASH:
            raise ShardSetError(f"unknown shard rule {s.shard_rule}")
        return ShardSet(s.shard_rule, s.shard_region_depth, s.shard_count, boxes)

    def shard_of_region(self, x: int, y: int, z: int) -> int:
        if self.rule == map_info_t.SHARD_RULE_HASH:
            return region_hash(x, y, z) % self.count
        if self.rule == map_info_t.SHARD_RULE_BOXES:
            for i, b in enumerate(self.boxes):
                if b[0] <= x < b[3] and b[1] <= y < b[4] and b[2] <= z < b[5]:
                    return i
            return self.count
        return 0

    def shard_of_key(self, key) -> int:
        s = TREE_DEPTH - self.region_depth
        return self.shard_of_region(key[0] >> s, key[1] >> s, key[2] >> s)


def shards_meeting(s: ShardSet, lo, hi) -> list:
    """The shards whose regions meet the key box lo .. hi (inclusive; shard_distance.cpp's shards_meeting)."""
    if s.count == 1:
        return [0]
    shift = TREE_DEPTH - s.region_depth
    top = (1 << TREE_DEPTH) - 1
    lo = [min(max(int(v), 0), top) for v in lo]
    hi = [min(max(int(v), 0), top) for v in hi]
    if any(h < l for l, h in zip(lo, hi)):
        return []
    r0, r1 = [v >> shift for v in lo], [v >> shift for v in hi]
    if s.rule == map_info_t.SHARD_RULE_BOXES:
        return [i for i, b in enumerate(s.boxes) if all(r0[a] < b[3 + a] and r1[a] >= b[a] for a in range(3))]
    met = {s.shard_of_region(x, y, z) for z in range(r0[2], r1[2] + 1) for y in range(r0[1], r1[1] + 1)
           for x in range(r0[0], r1[0] + 1)}
    return sorted(i for i in met if i < s.count)


def shards_for_rays(s: ShardSet, origins, directions, max_range: float, resolution: float) -> list:
    """The shards a batch of rays can reach (shard_rays.cpp's shards_for_rays): for the boxes rule with a
    finite max range, the boxes meeting each ray's key box from its origin to past max_range (2 keys wider);
    every shard otherwise (a hashed set's small regions meet every shard along a few metres)."""
    import numpy as np

    every = list(range(s.count))
    if s.rule != map_info_t.SHARD_RULE_BOXES or not max_range > 0 or not math.isfinite(max_range):
        return every
    dirs = np.asarray(directions, dtype=np.float32).reshape(-1, 3).astype(np.float64)
    orig = np.broadcast_to(np.asarray(origins, dtype=np.float32).reshape(-1, 3), dirs.shape).astype(np.float64)
    asked = set()
    for o, d in zip(orig, dirs):
        norm = math.sqrt(float(d @ d))
        if not norm > 0 or not math.isfinite(norm):
            return every
        lo, hi = [], []
        for a in range(3):
            k0 = _axis_key(o[a], resolution)
            end = o[a] + d[a] / norm * (float(max_range) + 2 * resolution)  # castRay stops within a diagonal
            if k0 is None or not math.isfinite(end):
                return every
            k1 = _axis_key(end, resolution)
            if k1 is None:
                k1 = 0 if end < 0 else (1 << TREE_DEPTH) - 1
            lo.append(min(k0, k1) - 2)
            hi.append(max(k0, k1) + 2)
        asked.update(shards_meeting(s, lo, hi))
    return sorted(asked) or [0]  # no ray: one shard answers the empty batch


def _axis_key(c: float, resolution: float):
    """shard_distance.cpp's voxel_key of one double coordinate: its key, or None outside the range."""
    if not abs(c) < resolution * _KEY_ORIGIN:
        return None
    return int(math.floor((1.0 / resolution) * c)) + _KEY_ORIGIN


def voxel_key(point, resolution: float):
    """OctoMap's coordToKeyChecked of a float32 point: a key triple, or None outside the range."""
    import numpy as np

    key = []
    for c in np.asarray(point, dtype=np.float32).astype(np.float64).reshape(3):
        scaled = np.floor((1.0 / resolution) * c)
        if not -_KEY_ORIGIN <= scaled < _KEY_ORIGIN:
            return None
        key.append(int(scaled) + _KEY_ORIGIN)
    return tuple(key)


@dataclass
class ShardAnswer:
    value: object                                        # the merged answer
    missing: Dict[int, str] = field(default_factory=dict)  # shard index -> why it did not answer

    @property
    def partial(self) -> bool:
        return bool(self.missing)


class ShardClient:
    """The shards of namespace `namespace` (default $OCTOMAP_RT_NAMESPACE) on one LCM URL.
    discover() waits for every shard's status; a shard not heard within `timeout_s` is missing
    (raises ServerTimeout unless `partial`, then its queries are marked partial)."""

    def __init__(self, url: Optional[str] = None, transport=None, namespace: Optional[str] = None,
                 client_id: str = "", timeout_s: float = 5.0, partial: bool = False):
        self.ns = namespace_from(namespace)
        self.transport = transport or open_transport(url)
        self.client_id = client_id or new_client_id()
        self.set, self.statuses, self.resolution = self.discover(timeout_s, partial)
        self.shards = [MapClient(transport=self.transport, client_id=self.client_id,
                                 namespace=shard_namespace(self.ns, i) if self.set.count > 1 else self.ns)
                       for i in range(self.set.count)]

    def discover(self, timeout_s: float, partial: bool):
        """(ShardSet, {index: latest server_status_t}, resolution) from the namespace's statuses."""
        statuses, sets = {}, []

        def take(_channel, data):
            try:
                s = server_status_t.decode(data)
            except ValueError:
                return
            sets.append(ShardSet.of_status(s))
            if sets[-1] != sets[0]:
                raise ShardSetError(f"two shard sets in namespace {self.ns!r}: {sets[0]} and {sets[-1]}")
            statuses[s.shard_index] = s

        sub = self.transport.subscribe(Channels(self.ns).status, take)
        try:
            deadline = time.monotonic() + timeout_s
            while time.monotonic() < deadline and not (sets and len(statuses) == sets[0].count):
                self.transport.handle(0.1)
        finally:
            self.transport.unsubscribe(sub)
        if not sets:
            raise ServerTimeout(f"no shard of namespace {self.ns!r} sent a status within {timeout_s} s")
        missing = [i for i in range(sets[0].count) if i not in statuses]
        if missing and not partial:
            raise ServerTimeout(f"shards {missing} of {sets[0].count} sent no status within {timeout_s} s")
        return sets[0], statuses, next(iter(statuses.values())).resolution

    def close(self) -> None:
        self.transport.close()

    def wait(self, robot_id: str = "", seq: int = -1, timeout_s: float = 5.0,
             min_snapshot_ids: Optional[Dict[int, int]] = None) -> None:
        """Read-your-writes across the set: every later query waits on each shard it asks until
        that shard applied robot `robot_id`'s scan `seq` (every shard applies every scan) and
        reached its own map state id `min_snapshot_ids[i]` (each shard's ids are its own), at
        most `timeout_s` there; a shard that cannot is missing (the answer partial). No
        arguments: no wait."""
        for i, c in enumerate(self.shards):
            w = Wait(min_snapshot_id=(min_snapshot_ids or {}).get(i, 0), robot_id=robot_id, seq=seq,
                     timeout_s=timeout_s)
            c.queries.wait = w if w.waits() else None

    def _ask(self, indices, ask) -> ShardAnswer:
        """{index: ask(index, its MapClient)} of the shards asked; a shard that fails (or was not
        heard) is named in `missing` with why."""
        got, missing = {}, {}
        for i in indices:
            if i not in self.statuses:
                missing[i] = "no status heard"
                continue
            try:
                got[i] = ask(i, self.shards[i])
            except (QueryError, ServerTimeout, FetchError, TimeoutError) as e:
                missing[i] = str(e)
        return ShardAnswer(got, missing)

    def query_points(self, points, depth: int = 0) -> ShardAnswer:
        """(occupancy, probability) as MapClient.query_points; each point asked of its voxel's
        shard (every shard at a depth above the region depth: the largest probability wins)."""
        import numpy as np

        pts = np.asarray(points, dtype=np.float32).reshape(-1, 3)
        occ = np.full(len(pts), UNKNOWN, dtype=np.int8)
        prob = np.full(len(pts), -1.0, dtype=np.float32)
        coarse = 0 < depth < self.set.region_depth
        owner = np.array([self.set.count if k is None else self.set.shard_of_key(k)
                          for k in (voxel_key(p, self.resolution) for p in pts)], dtype=np.int64)
        mine = {i: (np.arange(len(pts)) if coarse else np.nonzero(owner == i)[0]) for i in range(self.set.count)}
        a = self._ask([i for i in mine if len(mine[i])], lambda i, c: c.query_points(pts[mine[i]], depth))
        for i, (o, p) in a.value.items():
            idx = mine[i]
            better = p > prob[idx]
            prob[idx[better]], occ[idx[better]] = p[better], o[better]
        return ShardAnswer((occ, prob), a.missing)

    def cast_rays(self, origins, directions, max_range: float = -1.0, ignore_unknown: bool = False) -> ShardAnswer:
        """(hit, end_state, end points) as MapClient.cast_rays: the one map's castRay answers, asked of
        the shards the rays can reach (shards_for_rays)."""
        import numpy as np

        dirs = np.asarray(directions, dtype=np.float32).reshape(-1, 3)
        orig = np.broadcast_to(np.asarray(origins, dtype=np.float32).reshape(-1, 3), dirs.shape)
        reach = shards_for_rays(self.set, orig, dirs, max_range, self.resolution)
        a = self._ask(reach, lambda i, c: c.cast_rays(orig, dirs, max_range, ignore_unknown))
        n = len(dirs)
        hit, state, ends = np.zeros(n, dtype=bool), np.full(n, UNKNOWN, dtype=np.int8), np.zeros((n, 3), np.float32)
        for j in range(n):
            o = voxel_key(orig[j], self.resolution)
            best = None
            for i, (h, st, e) in a.value.items():
                k = voxel_key(e[j], self.resolution) if o is not None else None
                steps = 0 if k is None else sum(abs(k[d] - o[d]) for d in range(3))
                owned = k is not None and self.set.shard_of_key(k) == i
                if best is None or steps < best[0] or (steps == best[0] and owned and not best[1]):
                    best = (steps, owned, h[j], st[j], e[j])
            if best is not None:
                hit[j], state[j], ends[j] = best[2], best[3], best[4]
        return ShardAnswer((hit, state, ends), a.missing)

    def box(self, boxes) -> ShardAnswer:
        """{'occupied', 'free', 'unknown'} as MapClient.box, summed over the shards."""
        a = self._ask(range(self.set.count), lambda i, c: c.box(boxes))
        if not a.value:
            return ShardAnswer(None, a.missing)
        parts = list(a.value.values())
        total = parts[0]["occupied"] + parts[0]["free"] + parts[0]["unknown"]  # the boxes' voxels
        occ = sum(p["occupied"] for p in parts)
        free = sum(p["free"] for p in parts)
        return ShardAnswer({"occupied": occ, "free": free, "unknown": total - occ - free}, a.missing)

    def grid(self, z_min: float, z_max: float, cell_size: float = 0.0) -> ShardAnswer:
        """(cells, origin, cell size) as MapClient.grid: per cell the most of the shards' cells
        (occupied > free > unknown), on the union of their extents."""
        import numpy as np

        a = self._ask(range(self.set.count), lambda i, c: c.grid(z_min, z_max, cell_size))
        if not a.value:
            return ShardAnswer(None, a.missing)
        parts = list(a.value.values())
        size = parts[0][2]
        lo = [min(round(p[1][d] / size) for p in parts) for d in range(2)]
        hi = [max(round(p[1][d] / size) + p[0].shape[1 - d] for p in parts) for d in range(2)]
        cells = np.full((hi[1] - lo[1], hi[0] - lo[0]), UNKNOWN, dtype=np.int8)
        assert UNKNOWN < FREE < OCCUPIED  # so the most of the cells is their maximum
        for c, origin, _ in parts:
            i0, j0 = round(origin[0] / size) - lo[0], round(origin[1] / size) - lo[1]
            view = cells[j0:j0 + c.shape[0], i0:i0 + c.shape[1]]
            np.maximum(view, c, out=view)
        return ShardAnswer((cells, (lo[0] * size, lo[1] * size), size), a.missing)

    def fetch_map(self, timeout_s: float = 30.0) -> ShardAnswer:
        """The shards' fresh snapshots merged: (BtMap of every shard's leaves, {index: (snapshot
        id, map epoch)}). The shards' voxels are disjoint, so the merged leaves cover the one
        map's voxels exactly (pruned differently where a leaf would span shards)."""
        import numpy as np

        def one(_i, c):
            snap = c.fetch_snapshot("bt", timeout_s)
            return read_bt(snap.data), (snap.snapshot_id, snap.map_epoch)

        a = self._ask(range(self.set.count), one)
        if not a.value:
            return ShardAnswer(None, a.missing)
        maps = [m for m, _ in a.value.values()]
        merged = BtMap(self.resolution, np.concatenate([m.occupied for m in maps]),
                       np.concatenate([m.occupied_size for m in maps]), np.concatenate([m.free for m in maps]),
                       np.concatenate([m.free_size for m in maps]))
        return ShardAnswer((merged, {i: s for i, (_, s) in a.value.items()}), a.missing)
