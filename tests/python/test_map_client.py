"""MapClient against a real octomap-rt-server in a network namespace, and the .bt reader
against the C++ build's own leaf counts. Debian's python3 and python3-numpy only."""

import os
import re
import struct
import subprocess
import tempfile
import unittest

import numpy as np

import octomap_rt
from server_fixture import CLI, ServerTestCase, voxel_keys


def raw_t_data(payload: bytes) -> bytes:
    """The map bytes of an octomap.raw_t (fingerprint, utime, transform[4][4], length, data)."""
    (length,) = struct.unpack_from(">i", payload, 8 + 8 + 128)
    return payload[8 + 8 + 128 + 4:8 + 8 + 128 + 4 + length]


class BtReaderTest(unittest.TestCase):
    def test_leaf_counts_match_the_cpp_build(self):
        out = tempfile.mkdtemp(prefix="ort-py-bt-")
        path = os.path.join(out, "synthetic.bt")
        summary = subprocess.run([CLI, "build", "synthetic", "-r", "0.2", "-o", path, "-q"], check=True,
                                 capture_output=True, text=True).stdout
        stored = re.search(r"leaves stored:\s+(\d+) free, (\d+) occupied", summary)
        finest = re.search(r"finest level:\s+(\d+) free, (\d+) occupied", summary)
        m = octomap_rt.read_bt_file(path)
        self.assertEqual(m.resolution, 0.2)
        # The .bt is OcTree::writeBinary's (maximum likelihood, pruned): at most the tree's stored leaves,
        # and, below, exactly its finest-level free and occupied volume.
        self.assertLessEqual(len(m.free) + len(m.occupied), int(stored[1]) + int(stored[2]), summary)
        # Pruned leaves are larger boxes: their volume in finest voxels gives the finest counts.
        finest_free = int(np.round(np.sum((m.free_size / 0.2) ** 3)))
        finest_occ = int(np.round(np.sum((m.occupied_size / 0.2) ** 3)))
        self.assertEqual((finest_free, finest_occ), (int(finest[1]), int(finest[2])), summary)
        # The synthetic scene's rooms span x -1..19, y -1..11 (walls included).
        self.assertAlmostEqual(m.occupied[:, 0].min(), -0.9, places=6)
        self.assertAlmostEqual(m.occupied[:, 0].max(), 18.9, places=6)

    def test_not_a_bt_file(self):
        with self.assertRaises(octomap_rt.BtFormatError):
            octomap_rt.read_bt(b"# Octomap OcTree file\nid OcTree\nres 0.1\ndata\n")


class MapClientTest(ServerTestCase):
    def test_status_and_a_python_scan_reach_the_map(self):
        first = self.client.status(timeout_s=60)
        self.assertEqual(first.backend, "cpu")
        self.assertIn(first.state, (octomap_rt.server_status_t.STATE_STARTING, octomap_rt.server_status_t.STATE_RUNNING))
        # A wall 2 m in front of a sensor at (0, 0, 1): 41 x 21 points on the plane x = 2.
        ys, zs = np.meshgrid(np.linspace(-1, 1, 41), np.linspace(-0.5, 0.5, 21))
        wall = np.stack([np.full(ys.size, 2.0), ys.ravel(), zs.ravel()], axis=1)
        seq = self.client.publish_scan(wall, robot_id="py1", origin=(0.0, 0.0, 1.0))
        self.assertEqual(seq, 0)
        applied = self.client.wait_for(
            "OCTOMAP_RT_STATUS", octomap_rt.server_status_t.decode, timeout_s=60,
            accept=lambda s: any(r.robot_id.lower() == "py1" and r.scans_applied == 1 for r in s.robots))
        robot = [r for r in applied.robots if r.robot_id.lower() == "py1"][0]
        self.assertEqual((robot.scans_received, robot.scans_rejected, robot.points_applied), (1, 0, len(wall)))
        # The server's map (octomap.raw_t on OCTOMAP, .bt bytes) holds the wall where it was sent.
        raw = self.client.wait_for("OCTOMAP", raw_t_data, timeout_s=30,
                                   accept=lambda data: len(octomap_rt.read_bt(data).occupied) > 0)
        m = octomap_rt.read_bt(raw)
        expected = voxel_keys(wall + np.array([0.0, 0.0, 1.0]))
        on_plane = {k for k in voxel_keys(m.occupied) if k[0] == 20}  # voxels x in [2.0, 2.1)
        self.assertEqual(on_plane, expected)
        self.assertGreater(len(m.free), 0)

    def test_status_times_out_on_a_silent_channel(self):
        with self.assertRaises(octomap_rt.ServerTimeout):
            self.client.wait_for("NOBODY_SENDS_THIS", bytes, timeout_s=0.5)


if __name__ == "__main__":
    unittest.main()
