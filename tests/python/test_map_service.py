"""The map service from Python (fetch_snapshot, map_info) against a real octomap-rt-server in
a network namespace, checked against the C++ client (`octomap-rt map get`)."""

import os
import subprocess
import unittest

import octomap_rt
from server_fixture import CLI, ServerTestCase, voxel_keys


class MapServiceTest(ServerTestCase):
    def test_snapshot_and_map_info_match_the_cpp_client(self):
        ends = self.publish_wall(3.0, "py2")
        snap = self.client.fetch_snapshot("bt", timeout_s=60)
        self.assertGreaterEqual(snap.num_scans, 1)
        # The C++ client fetches the same map: same bytes (the map did not change in between).
        cpp_path = os.path.join(self.dir, "cpp.bt")
        subprocess.run([CLI, "map", "get", "-o", cpp_path, "--lcm-url", self.url, "-q"], check=True,
                       timeout=120, capture_output=True)
        with open(cpp_path, "rb") as f:
            self.assertEqual(snap.data, f.read())
        m = octomap_rt.read_bt(snap.data)
        on_plane = {k for k in voxel_keys(m.occupied) if k[0] == 30}  # voxels x in [3.0, 3.1)
        self.assertEqual(on_plane, voxel_keys(ends))
        info = self.client.map_info(timeout_s=10)
        self.assertEqual(info.resolution, 0.1)
        self.assertGreaterEqual(info.snapshot_id, snap.snapshot_id)
        full = self.client.fetch_snapshot("ot", timeout_s=60, snapshot_id=0)
        self.assertTrue(full.data.startswith(b"# Octomap OcTree file"))



if __name__ == "__main__":
    unittest.main()
