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
