"""Every shard's deltas in one mirror (octomap_rt.ShardMirror, issue 26): three shards of one
namespace (octomap-rt-server --shard i/3) and one whole daemon in another hear a robot's real scans
(3DTK, `octomap-rt replay`) while a ShardMirror follows the shards. The merged mirror equals every
shard's own snapshot and the whole daemon's map, each shard followed by deltas (one snapshot); a
reset of one shard (a new epoch) resyncs that shard alone; a stopped shard is said late."""

import os
import signal
import subprocess
import time
import unittest

import octomap_rt
from octomap_rt import ShardMirror, canonical_leaves, read_bt_leaves
from server_fixture import CLI, ShardSetGroup

DATA = os.environ.get("OCTOMAP_RT_DATA", "")
GRAPH = os.path.join(DATA, "3dtk_dat", "3dtk_3scans.graph")
SHARDS = 3
TOKEN = "py-shard-mirror-token-0123"


def snapshot_leaves(client):
    """A server's fresh snapshot as the mirror holds it: (id, epoch, canonical class leaves)."""
    snap = client.fetch_snapshot("bt", timeout_s=60)
    return snap.snapshot_id, snap.map_epoch, canonical_leaves(read_bt_leaves(snap.data)[1])


@unittest.skipUnless(os.path.exists(GRAPH), "no 3DTK data")
class ShardMirrorTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.group = ShardSetGroup("ort-py-shard-mirror-", 17, 11, SHARDS, 12, ["-r", "0.2", "--control-token", TOKEN])
        cls.url, cls.servers = cls.group.url, cls.group.servers
        cls.whole, cls.shards = cls.group.whole, cls.group.shards

    @classmethod
    def tearDownClass(cls):
        cls.group.stop()

    def replay(self, ns, mirror, *more):
        """Publishes the scans to namespace `ns` (every 4th point) while `mirror` follows."""
        p = subprocess.Popen([CLI, "replay", GRAPH, "--robot", "rover", "--unpaced", "--decimate", "4", "-q",
                              "--namespace", ns, "--lcm-url", self.url] + list(more),
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        while p.poll() is None:
            mirror.spin(0.1)
        self.assertEqual(p.returncode, 0, p.stdout.read())

    def wait_applied(self, client, count, statuses):
        """Waits for `statuses` statuses (one per server) that each say `count` scans applied."""
        self.group.wait_statuses(client, lambda s: sum(r.scans_applied for r in s.robots) == count, statuses)

    def catch_up(self, mirror, want):
        """Spins until every shard's part is at the map state (id, epoch) of its snapshot in `want`."""
        deadline = time.monotonic() + 30
        at = lambda: [(m.version, m.epoch) for m in mirror.mirrors]  # noqa: E731
        while at() != [w[:2] for w in want] and time.monotonic() < deadline:
            mirror.spin(0.2)
        self.assertEqual(at(), [w[:2] for w in want])

    def test_one_mirror_follows_every_shard(self):
        mirror = ShardMirror(self.shards)
        mirror.sync()  # the empty maps: the scans below reach the mirror as deltas
        self.assertEqual(mirror.merged().missing, {})
        feed = octomap_rt.MapClient(transport=self.shards.transport, namespace="campus")
        self.replay("campus", mirror)
        self.replay("one", mirror)
        self.wait_applied(feed, 3, SHARDS)
        self.wait_applied(self.whole, 3, 1)
        parts = [snapshot_leaves(c) for c in self.shards.shards]
        self.catch_up(mirror, parts)
        merged = mirror.merged()
        self.assertFalse(merged.partial, merged.missing)
        self.assertEqual(merged.shortfall, "")
        _, _, whole = snapshot_leaves(self.whole)
        self.assertGreater(sum(whole.values()), 1000)  # occupied leaves
        self.assertEqual(canonical_leaves(merged.leaves), whole)
        for i, m in enumerate(mirror.mirrors):  # each shard's part: its snapshot, followed by deltas
            self.assertEqual(canonical_leaves(m.leaves), parts[i][2], f"shard {i}")
            self.assertEqual(m.stats.snapshots, 1, f"shard {i}")
            self.assertGreater(m.stats.voxels_applied, 1000, f"shard {i}")
        self.assertEqual(mirror.refused_infos, [0] * SHARDS)

        # Shard 1 alone is reset (a new epoch), then one more scan: shard 1 resyncs, the others not.
        epoch1 = mirror.mirrors[1].epoch
        octomap_rt.MapClient(transport=self.shards.transport, namespace="campus_SHARD1").reset_map(TOKEN)
        mirror.spin(1.5)
        self.replay("campus", mirror, "--count", "1", "--first-seq", "3")
        self.wait_applied(feed, 4, SHARDS)
        parts = [snapshot_leaves(c) for c in self.shards.shards]
        self.catch_up(mirror, parts)
        merged = mirror.merged()
        want = {}
        for p in parts:
            want.update(p[2])
        self.assertEqual(canonical_leaves(merged.leaves), canonical_leaves(want))
        self.assertNotEqual(mirror.mirrors[1].epoch, epoch1)
        self.assertGreaterEqual(mirror.mirrors[1].stats.epoch_changes, 1)
        self.assertEqual([m.stats.snapshots for m in mirror.mirrors], [1, 2, 1])

        # Shard 2 stops: the mirror says it is late.
        self.servers[2].send_signal(signal.SIGTERM)
        self.assertEqual(self.servers[2].wait(timeout=60), 0)
        mirror.spin(4.0)
        merged = mirror.merged()
        self.assertEqual(list(merged.late), [2])
        self.assertIn("shard 2 of 3 late (no map info for", merged.shortfall)
        mirror.close()


if __name__ == "__main__":
    unittest.main()
