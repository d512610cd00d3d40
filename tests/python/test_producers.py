"""README's "Connect your robot" producers, built and run: the C++ one (client/examples/
publish_scan.cpp) and the Python one (client/bindings/python/examples/publish_scan.py) each publish a
real scan with NaN no-returns to a real octomap-rt-server; the server applies every finite
point and counts the NaN ones for that robot."""

import os
import subprocess
import sys
import time
import unittest

from server_fixture import ServerTestCase

DATA = os.environ.get("OCTOMAP_RT_DATA", "")
CPP_EXAMPLE = os.environ.get("OCTOMAP_RT_PUBLISH_EXAMPLE", "")
PY_EXAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "client", "bindings", "python", "examples",
                          "publish_scan.py")
POINTS = 88206  # octomap_share's scan.dat (and scan_dat.graph, made from it)
NAN = (POINTS + 9) // 10  # every tenth point a no-return


class ProducerExamplesTest(ServerTestCase):
    def robot_stats(self, robot_id, timeout_s=60.0):
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            for r in self.client.status(timeout_s=5.0).robots:
                if r.robot_id.lower() == robot_id and r.scans_received and r.queue_depth == 0:
                    return r
        self.fail(f"no status of {robot_id} within {timeout_s} s")

    def check(self, robot_id):
        r = self.robot_stats(robot_id)
        self.assertEqual((r.scans_received, r.scans_applied, r.scans_rejected), (1, 1, 0))
        self.assertEqual(r.points_applied, POINTS - NAN)
        self.assertEqual(dict(zip(r.point_drop_reason, r.point_drop_count)), {"non-finite": NAN})

    def test_cpp_producer(self):
        out = subprocess.run([CPP_EXAMPLE, os.path.join(DATA, "octomap_share", "scan_dat.graph"), self.url, "cpprobot"],
                             check=True, capture_output=True, text=True, timeout=60)
        self.assertIn(f"published {POINTS} points", out.stdout)
        self.check("cpprobot")

    def test_python_producer(self):
        out = subprocess.run([sys.executable, PY_EXAMPLE, os.path.join(DATA, "octomap_share", "scan.dat.bz2"),
                              self.url, "pyrobot"], check=True, capture_output=True, text=True, timeout=120,
                             env=dict(os.environ))
        self.assertIn(f"published {POINTS} points ({NAN} NaN)", out.stdout)
        self.check("pyrobot")


if __name__ == "__main__":
    unittest.main()
