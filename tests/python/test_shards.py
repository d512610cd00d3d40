"""The Python shard client (issue 26): three shards of one namespace (octomap-rt-server --shard i/3,
small regions so every wall crosses many) and one whole daemon in another namespace get the same
scans; octomap_rt.shards.ShardClient finds the shards by their statuses, and its routed points,
rays (stopping at unknown space and passing it), box counts, grid and merged snapshot equal the
whole daemon's answers, also right after a scan when they wait for it (read-your-writes). With a
shard stopped the answers say it is missing (partial)."""

import signal
import time
import unittest

import numpy as np

import octomap_rt
from octomap_rt.queries import Wait
from octomap_rt.shards import ShardClient, ShardSet, shards_for_rays
from octomap_rt import map_info_t
from server_fixture import ShardSetGroup

SHARDS = 3
ROBOT = "pyshard"


def leaf_voxels(leaves, sizes, resolution):
    """The finest voxel keys (minus 32768) the leaves cover."""
    out = set()
    for c, s in zip(leaves, sizes):
        n = int(round(s / resolution))
        lo = np.floor(c / resolution + 1e-6 - n / 2).astype(int)
        for i in range(n):
            for j in range(n):
                for k in range(n):
                    out.add((lo[0] + i, lo[1] + j, lo[2] + k))
    return out


class ShardSetTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.group = ShardSetGroup("ort-py-shards-", 13, 7, SHARDS, 14, ["-r", "0.1", "--query-lock-ms", "2000"])
        cls.url, cls.servers = cls.group.url, cls.group.servers
        cls.whole, cls.shards = cls.group.whole, cls.group.shards
        cls.feed = octomap_rt.MapClient(cls.url, namespace="campus")
        # Two walls and a floor patch from two sensor positions, to both maps.
        walls = [(np.array([[4.0, y, z] for y in np.linspace(-2, 2, 41) for z in np.linspace(0, 1.5, 16)]),
                  (0.0, 0.0, 0.5)),
                 (np.array([[x, 3.0, z] for x in np.linspace(-1, 3, 41) for z in np.linspace(0, 1.5, 16)]),
                  (0.5, -0.5, 0.8))]
        for pts, origin in walls:
            for c in (cls.whole, cls.feed):
                c.publish_scan(pts - np.asarray(origin), robot_id=ROBOT, origin=origin)
        want = len(walls)

        def applied(s):
            return any(r.robot_id.lower() == ROBOT and r.scans_applied == want for r in s.robots)

        cls.whole.wait_for(cls.whole.channels.status, octomap_rt.server_status_t.decode, applied, timeout_s=60)
        cls.group.wait_statuses(cls.feed, applied, SHARDS, timeout_s=60)

    @classmethod
    def tearDownClass(cls):
        cls.feed.close()
        cls.group.stop()

    def test_1_routed_answers_equal_the_whole_daemon(self):
        self.assertEqual(self.shards.set.count, SHARDS)
        self.assertEqual(sorted(self.shards.statuses), list(range(SHARDS)))
        # The merged snapshot covers the whole map's voxels, each with its state.
        merged = self.shards.fetch_map(timeout_s=60)
        self.assertFalse(merged.partial, merged.missing)
        m, ids = merged.value
        self.assertEqual(sorted(ids), list(range(SHARDS)))
        self.assertTrue(all(epoch != 0 for _, epoch in ids.values()), ids)  # each shard's epoch beside it
        w = self.whole.fetch_map(timeout_s=60)
        occupied = leaf_voxels(w.occupied, w.occupied_size, 0.1)
        self.assertGreater(len(occupied), 500)
        self.assertEqual(leaf_voxels(m.occupied, m.occupied_size, 0.1), occupied)
        self.assertEqual(leaf_voxels(m.free, m.free_size, 0.1), leaf_voxels(w.free, w.free_size, 0.1))
        # Points: a grid through both walls and the free space in front of them.
        pts = np.array([[x, y, z] for x in np.arange(-1.05, 4.5, 0.2) for y in np.arange(-2.05, 3.5, 0.2)
                        for z in (0.25, 0.75, 1.25)] + w.occupied[::7].tolist())
        got = self.shards.query_points(pts)
        self.assertFalse(got.partial, got.missing)
        want = self.whole.query_points(pts)
        np.testing.assert_array_equal(got.value[0], want[0])
        np.testing.assert_array_equal(got.value[1], want[1])
        self.assertEqual(len(set(want[0].tolist())), 3)  # unknown, free and occupied points
        # Rays from the first sensor over a fan: stopping at unknown space, and passing it.
        dirs = np.array([[np.cos(a), np.sin(a), e] for a in np.linspace(-0.9, 1.6, 60) for e in (-0.2, 0.0, 0.3)])
        for ignore in (False, True):
            got = self.shards.cast_rays((0.0, 0.0, 0.5), dirs, max_range=12.0, ignore_unknown=ignore)
            self.assertFalse(got.partial, got.missing)
            want = self.whole.cast_rays((0.0, 0.0, 0.5), dirs, max_range=12.0, ignore_unknown=ignore)
            for g, w_ in zip(got.value, want):
                np.testing.assert_array_equal(g, w_)
            self.assertTrue(want[0].any())
        # Boxes and the grid of a band.
        boxes = [[3.5, -2.5, 0.0, 4.5, 2.5, 1.6], [-1.0, -1.0, 0.0, 3.5, 3.5, 1.0]]
        got = self.shards.box(boxes)
        want = self.whole.box(boxes)
        for k in ("occupied", "free", "unknown"):
            np.testing.assert_array_equal(got.value[k], want[k])
        got = self.shards.grid(0.45, 1.05)
        cells, origin, size = self.whole.grid(0.45, 1.05)
        g_cells, g_origin, g_size = got.value
        self.assertEqual(g_size, size)
        # The merged grid spans the union of the shards' extents: the whole grid lies inside it.
        i0, j0 = round((origin[0] - g_origin[0]) / size), round((origin[1] - g_origin[1]) / size)
        np.testing.assert_array_equal(g_cells[j0:j0 + cells.shape[0], i0:i0 + cells.shape[1]], cells)

    def test_1b_read_your_writes_across_the_shards(self):
        # A wall in space no scan saw, to both maps, and at once queries that wait for it: on every
        # shard asked (each applies every scan) and on the whole daemon. Without the wait the
        # points would be unknown until the scan is applied.
        wall = np.array([[-6.0, y, z] for y in np.linspace(-2, 2, 41) for z in np.linspace(0, 1.5, 16)])
        origin = (-2.0, 0.0, 0.5)
        seqs = [c.publish_scan(wall - np.asarray(origin), robot_id=ROBOT, origin=origin)
                for c in (self.whole, self.feed)]
        self.assertEqual(seqs[0], seqs[1])
        self.shards.wait(ROBOT, seqs[1], timeout_s=30)
        self.whole.queries.wait = Wait(robot_id=ROBOT, seq=seqs[0], timeout_s=30)
        try:
            got = self.shards.query_points(wall)
            self.assertFalse(got.partial, got.missing)
            want = self.whole.query_points(wall)
            np.testing.assert_array_equal(got.value[0], want[0])
            np.testing.assert_array_equal(got.value[1], want[1])
            self.assertGreater(int((want[0] == octomap_rt.OCCUPIED).sum()), len(wall) // 2)
            # A state id shard 1 does not reach in time: that shard is named, the answer partial.
            self.shards.wait(timeout_s=0.2, min_snapshot_ids={1: 10 ** 9})
            got = self.shards.query_points(wall)
            self.assertEqual(list(got.missing), [1])
        finally:
            self.shards.wait()
            self.whole.queries.wait = None

    def test_2_a_missing_shard_makes_the_answers_partial(self):
        self.servers[2].send_signal(signal.SIGTERM)
        self.servers[2].wait(timeout=60)
        time.sleep(1.5)  # its last status is gone from the bus
        c = ShardClient(transport=octomap_rt.open_transport(self.url), namespace="campus", timeout_s=2.5,
                        partial=True)
        try:
            self.assertEqual(c.set.count, SHARDS)
            got = c.cast_rays((0.0, 0.0, 0.5), [[1.0, 0.0, 0.0]], max_range=10.0)
            self.assertEqual(list(got.missing), [2])
            self.assertTrue(got.partial)
            t = octomap_rt.open_transport(self.url)
            with self.assertRaises(octomap_rt.ServerTimeout):  # without partial: refused
                ShardClient(transport=t, namespace="campus", timeout_s=2.5)
            t.close()
        finally:
            c.close()


class ShardRaysRouteTest(unittest.TestCase):
    """ShardClient.cast_rays asks only the shards a ray can reach on a boxes set (shards_for_rays, as the C++
    client's ShardRays test checks on real maps): every voxel along each ray, to a voxel's diagonal past its
    max range, is owned by an asked shard, and short rays ask fewer shards than the set has. No daemon."""

    RES = 0.1
    # Four boxes of depth-13 regions (0.8 m at 0.1 m) meeting at x = 0, y = 0 (region 4096), every z.
    BOXES = ShardSet(map_info_t.SHARD_RULE_BOXES, 13, 4,
                     ((0, 0, 0, 4096, 4096, 8192), (4096, 0, 0, 8192, 4096, 8192),
                      (0, 4096, 0, 4096, 8192, 8192), (4096, 4096, 0, 8192, 8192, 8192)))

    def test_asked_shards_hold_every_voxel_a_ray_reaches(self):
        rng = np.random.default_rng(26)
        fewer = 0
        for max_range in (0.6, 2.0, 6.0):
            for _ in range(300):
                o = rng.uniform([-4, -4, 0], [4, 4, 2]).astype(np.float32)
                d = rng.normal(size=3).astype(np.float32)
                asked = shards_for_rays(self.BOXES, o, d, max_range, self.RES)
                fewer += len(asked) < self.BOXES.count
                u = d.astype(np.float64) / np.linalg.norm(d.astype(np.float64))
                t = np.arange(0.0, max_range + 1.8 * self.RES, self.RES / 8)
                along = (o.astype(np.float64) + t[:, None] * u).astype(np.float32).astype(np.float64)
                keys = {tuple(k) for k in (np.floor((1.0 / self.RES) * along).astype(np.int64) + (1 << 15))}
                for k in keys:
                    owner = self.BOXES.shard_of_key(k)
                    self.assertIn(owner, asked, f"ray {o} {d} range {max_range}: key {k} in shard {owner}")
        self.assertGreater(fewer, 300)  # most 0.6 m rays and many 2 m rays stay in one or two boxes

    def test_every_shard_without_a_max_range_or_for_the_hash_rule(self):
        o, d = (0.5, 0.5, 0.5), (1.0, 0.0, 0.0)
        self.assertEqual(shards_for_rays(self.BOXES, o, d, -1.0, self.RES), [0, 1, 2, 3])
        self.assertEqual(shards_for_rays(self.BOXES, o, d, float("inf"), self.RES), [0, 1, 2, 3])
        self.assertEqual(shards_for_rays(self.BOXES, o, (0.0, 0.0, 0.0), 2.0, self.RES), [0, 1, 2, 3])
        hashed = ShardSet(map_info_t.SHARD_RULE_HASH, 13, 3)
        self.assertEqual(shards_for_rays(hashed, o, d, 0.5, self.RES), [0, 1, 2])
        self.assertEqual(shards_for_rays(self.BOXES, o, d, 0.5, self.RES), [3])  # x, y > 0: the fourth box


if __name__ == "__main__":
    unittest.main()
