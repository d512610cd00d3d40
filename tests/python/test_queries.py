"""Occupancy queries from Python (points, rays, boxes, grid) and the planner example against a
real octomap-rt-server in a network namespace, checked against the map the server sends."""

import subprocess
import sys
import unittest

import numpy as np

import octomap_rt
from server_fixture import EXAMPLE, ServerTestCase, voxel_keys


class QueriesTest(ServerTestCase):
    def test_queries_agree_with_the_fetched_map(self):
        ends = self.publish_wall(4.0, "py3")
        m = self.client.fetch_map(timeout_s=60)
        # Points: every leaf centre of the snapshot as the server classifies it; far away unknown.
        occ, prob = self.client.query_points(m.occupied)
        self.assertTrue((occ == octomap_rt.OCCUPIED).all())
        self.assertTrue((prob > 0.5).all())
        occ, _ = self.client.query_points(np.resize(m.free, (6000, 3)))  # two messages (5000 a query)
        self.assertTrue((occ == octomap_rt.FREE).all())
        occ, prob = self.client.query_points([[50.0, 50.0, 50.0]])
        self.assertEqual((int(occ[0]), float(prob[0])), (octomap_rt.UNKNOWN, -1.0))
        # Rays from the sensor towards the wall stop in its voxels (x in [4.0, 4.1)).
        hit, state, ray_ends = self.client.cast_rays((0.0, 0.0, 0.5), [[1.0, 0.0, 0.0], [1.0, 0.2, 0.0]], max_range=10,
                                                ignore_unknown=True)
        self.assertTrue(hit.all())
        self.assertTrue((state == octomap_rt.OCCUPIED).all())
        self.assertTrue(((ray_ends[:, 0] >= 4.0) & (ray_ends[:, 0] < 4.1 + 1e-4)).all(), ray_ends)
        # Boxes: the wall's voxels counted; the grid of its band shows them.
        counts = self.client.box([[3.95, -1.05, 0.45, 4.05, 1.05, 1.55]])
        self.assertEqual(int(counts["occupied"][0]), len(voxel_keys(ends)))
        cells, (ox, oy), size = self.client.grid(0.45, 1.55)
        self.assertEqual(size, 0.1)
        i, j = int(np.floor((4.05 - ox) / size)), int(np.floor((0.05 - oy) / size))
        self.assertEqual(int(cells[j, i]), octomap_rt.OCCUPIED)
        # The planner example runs against the same server.
        out = subprocess.run([sys.executable, EXAMPLE, "--lcm-url", self.url, "--at", "0,0,1", "--band", "0.45:1.55"],
                             capture_output=True, text=True, timeout=120)
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("rays from", out.stdout)
        self.assertIn("nearest obstacle", out.stdout)


    def test_distance_to_the_wall(self):
        self.publish_wall(4.0, "pyd")
        self.client.fetch_map(timeout_s=60)  # the wall is in the map
        # One metre in front of the wall's middle: 1.0 m, the gradient away from it (-x).
        d, g = self.client.distance_points([[3.05, 0.05, 1.05], [-20.0, 0.0, 1.0]], max_distance=1.55, gradient=True)
        self.assertAlmostEqual(float(d[0]), 1.0, places=5)
        self.assertAlmostEqual(float(g[0, 0]), -1.0, places=5)
        self.assertAlmostEqual(float(d[1]), 1.55, places=5)  # nothing within reach: the clamp
        box = self.client.distance_box((3.01, -0.49, 0.51), (4.49, 0.49, 1.49), max_distance=1.55, gradient=True)
        self.assertEqual(box["distance"].shape, (10, 10, 15))  # corners inside voxels, not on their faces
        self.assertEqual(float(box["distance"].min()), 0.0)  # the wall's voxels
        # The box's cell holding (3.05, 0.05, 1.05) has the point query's distance.
        ox, oy, oz = box["origin"]
        i, j, k = (int(np.floor((v - o) / box["cell_size"])) for v, o in ((3.05, ox), (0.05, oy), (1.05, oz)))
        self.assertAlmostEqual(float(box["distance"][k, j, i]), float(d[0]), places=6)
        path = self.client.distance_path([[0.0, 0.01, 1.01], [3.45, 0.01, 1.01]], max_distance=1.55)
        self.assertEqual(path["num_samples"], 36)  # 35 steps of 0.0986 m, both ends
        self.assertAlmostEqual(path["min_distance"], 0.6, places=5)  # the last sample's voxel, 6 before the wall


if __name__ == "__main__":
    unittest.main()


class _BusyThenAnswer:
    """A transport standing in for a server that refuses the first `busy` grid queries as BUSY
    (a full queue, or the time bound under the map lock) and answers the next one."""

    def __init__(self, busy):
        self.busy, self.asked, self.pending, self.handlers = busy, [], [], {}

    def subscribe(self, channel, handler):
        self.handlers[channel] = handler
        return channel

    def unsubscribe(self, sub):
        self.handlers.pop(sub, None)

    def publish(self, channel, data):
        q = octomap_rt.grid_query_t.decode(data)
        self.asked.append(q.request_id)
        r = octomap_rt.grid_t()
        r.request_id, r.num_chunks = q.request_id, 1
        if len(self.asked) <= self.busy:
            r.status, r.num_chunks = octomap_rt.occupancy_reply_t.REPLY_BUSY, 0
            r.error = "refused: the time bound under the map lock"
        else:
            r.width, r.height, r.num_rows, r.cell_size = 1, 1, 1, 0.1
            r.cells, r.num_cells = [octomap_rt.OCCUPIED], 1
        self.pending.append((q.reply_channel, r.encode()))

    def handle(self, timeout_s=None):
        for channel, data in self.pending:
            if channel in self.handlers:
                self.handlers[channel](channel, data)
        n, self.pending = len(self.pending), []
        return n


class BusyRepliesTest(unittest.TestCase):
    def test_a_busy_reply_is_asked_again_until_it_is_answered(self):
        from octomap_rt.queries import QueryChannel, grid
        t = _BusyThenAnswer(busy=3)
        q = QueryChannel(t, "busy-test", timeout_s=5.0)
        cells, _, size = grid(q, 0.0, 1.0)
        self.assertEqual(int(cells[0, 0]), octomap_rt.OCCUPIED)
        self.assertEqual((q.busy_retries, len(t.asked), len(set(t.asked))), (3, 4, 4))

    def test_busy_past_the_timeout_is_an_error_that_says_why(self):
        from octomap_rt.queries import QueryChannel, QueryError, grid
        q = QueryChannel(_BusyThenAnswer(busy=10 ** 6), "busy-test", timeout_s=0.3)
        with self.assertRaisesRegex(QueryError, "status 3.*time bound under the map lock"):
            grid(q, 0.0, 1.0)
        self.assertGreater(q.busy_retries, 0)
