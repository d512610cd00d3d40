"""The planner example (client/bindings/python/examples/planner.py) against a real octomap-rt-server
with the demo's scene streamed to it (`octomap-rt replay synthetic`, as tools/run-demo does):
it prints a path from the corridor into a room through the door, and every waypoint of it is
free when the C++ client (`octomap-rt query points`) asks the server."""

import json
import math
import os
import subprocess
import sys
import unittest

import numpy as np

import octomap_rt
from server_fixture import CLI, EXAMPLE, ServerTestCase

# The synthetic scene's first three sensor poses: corridor (1.0, 1.5, 1.2), corridor (5.5, 1.4)
# and the first room (2.5, 6.0, 1.3). The corridor wall at y in [3, 3.2] has a door x in [2, 3].
START, GOAL = (1.0, 1.5), (2.5, 6.0)
BAND, HEIGHT, RADIUS = (0.3, 1.5), 1.25, 0.2
SCANS = 3


class PlannerExampleTest(ServerTestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        subprocess.run([CLI, "replay", "synthetic", "--robot", "demo", "--count", str(SCANS), "--rate", "4",
                        "--lcm-url", cls.url, "-q"], check=True, timeout=120, capture_output=True)
        cls.client.wait_for("OCTOMAP_RT_STATUS", octomap_rt.server_status_t.decode, timeout_s=120,
                            accept=lambda s: any(r.robot_id.lower() == "demo" and r.scans_applied == SCANS
                                                 for r in s.robots))

    def run_planner(self, *extra):
        args = [sys.executable, EXAMPLE, "--lcm-url", self.url, "--from", "%g,%g" % START, "--to", "%g,%g" % GOAL,
                "--band", "%g:%g" % BAND, "--height", str(HEIGHT), "--radius", str(RADIUS),
                "--at", "%g,%g,%g" % (*START, HEIGHT), *extra]
        out = subprocess.run(args, capture_output=True, text=True, timeout=120)
        self.assertEqual(out.returncode, 0, out.stdout + out.stderr)
        return out.stdout

    def test_path_through_the_door_with_every_waypoint_free(self):
        result = json.loads(self.run_planner("--json"))
        size = result["grid"]["cell_size"]
        self.assertEqual(size, 0.1)
        path = np.array(result["path"]["waypoints"])
        # From the start's cell to the goal's, one cell (8-connected) a step, at the robot's height.
        self.assertLessEqual(np.abs(path[0, :2] - START).max(), size / 2 + 1e-6)
        self.assertLessEqual(np.abs(path[-1, :2] - GOAL).max(), size / 2 + 1e-6)
        steps = np.abs(np.diff(path[:, :2], axis=0)).max(axis=1)
        self.assertTrue(((steps > size / 2) & (steps < size * 1.5)).all(), steps)
        self.assertTrue((path[:, 2] == HEIGHT).all())
        length = result["path"]["length_m"]
        self.assertGreater(length, math.dist(START, GOAL))  # the straight line crosses the wall at x 1.5
        self.assertLess(length, 2 * math.dist(START, GOAL))
        # It passes the corridor wall (y in [3, 3.2]) through the door (x in [2, 3]), clear of its jambs.
        in_wall = path[(path[:, 1] >= 2.9) & (path[:, 1] <= 3.3)]
        self.assertGreater(len(in_wall), 0)
        self.assertTrue(((in_wall[:, 0] > 2.0 + RADIUS) & (in_wall[:, 0] < 3.0 - RADIUS)).all(), in_wall)
        # Every waypoint free, as the C++ client hears it from the server.
        points_file = os.path.join(self.dir, "waypoints.txt")
        np.savetxt(points_file, path)
        cpp = subprocess.run([CLI, "query", "points", "--json", "--lcm-url", self.url, "--timeout", "30",
                              "--file", points_file], capture_output=True, text=True, timeout=120)
        self.assertEqual(cpp.returncode, 0, cpp.stderr)
        states = [p["state"] for p in json.loads(cpp.stdout)["results"]]
        self.assertEqual(states, ["free"] * len(path), cpp.stdout)
        # No occupied voxel in the band within one cell of a waypoint (the radius keeps two).
        boxes = [[x - size, y - size, BAND[0], x + size, y + size, BAND[1]] for x, y, _ in path]
        self.assertEqual(int(self.client.box(boxes)["occupied"].sum()), 0)

    def test_text_form_prints_the_path(self):
        lines = self.run_planner().splitlines()
        header = [line for line in lines if line.startswith("path from (1, 1.5) to (2.5, 6) at 1.25 m:")]
        self.assertEqual(len(header), 1, "\n".join(lines))
        count = int(header[0].split(": ")[1].split(" waypoints")[0])
        waypoints = [line for line in lines if line.startswith("  waypoint (") and line.split(": ")[1].startswith("free")]
        self.assertEqual(len(waypoints), count)
        self.assertTrue(any(line.startswith("nearest obstacle") for line in lines))

    def test_no_path_to_a_point_inside_a_wall(self):
        out = subprocess.run([sys.executable, EXAMPLE, "--lcm-url", self.url, "--from", "%g,%g" % START,
                              "--to", "4.0,3.1", "--band", "%g:%g" % BAND, "--height", str(HEIGHT)],
                             capture_output=True, text=True, timeout=120)
        self.assertEqual(out.returncode, 1, out.stdout + out.stderr)
        self.assertIn("no path over free cells", out.stderr)
        self.assertIn("goal cell", out.stderr)


if __name__ == "__main__":
    unittest.main()
