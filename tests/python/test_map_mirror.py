"""The Python MapMirror (octomap_rt.map_mirror) against a real octomap-rt-server in a network
namespace: it follows scans from two robots by deltas and equals the server's snapshot at the
same map state id, voxel class for voxel class; after a reset (a new epoch) it resyncs from a
snapshot and is equal again, while a mirror that does not resync keeps the old map."""

import time
import unittest

import numpy as np

import octomap_rt
from octomap_rt import canonical_leaves, read_bt_leaves
from server_fixture import ServerTestCase

TOKEN = "correct horse battery staple"


class MapMirrorTest(ServerTestCase):
    server_args = ["--control-token", TOKEN]

    def scan(self, x: float, robot_id: str, origin=(0.0, 0.0, 0.5)):
        """A wall of points at `x` (with a gap that later walls fill) from `origin`."""
        wall = np.array([[x, y, z] for y in np.linspace(-1.5, 1.5, 31) for z in np.linspace(0, 1.2, 13)
                         if not (abs(y) < 0.3 and x > 3)])
        self.client.publish_scan(wall, robot_id=robot_id, origin=origin)

    def follow(self, mirrors, timeout_s: float = 30.0):
        """Spins `mirrors` until the server has applied every scan sent and each mirror is at a
        fresh snapshot's state id; returns that snapshot."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            status = self.client.status(timeout_s=5)
            if all(r.queue_depth == 0 and r.scans_applied == self.sent.get(r.robot_id.lower(), 0)
                   for r in status.robots):
                snap = self.client.fetch_snapshot("bt")
                for _ in range(40):
                    if all(m.version >= snap.snapshot_id or m.epoch != snap.map_epoch for m in mirrors):
                        break
                    for m in mirrors:
                        m.spin(0.05)
                if all(m.version == snap.snapshot_id for m in mirrors if m.resync):
                    return snap
            for m in mirrors:
                m.spin(0.2)
        self.fail(f"the mirrors did not reach the server's state within {timeout_s} s")

    def publish(self, x, robot_id):
        self.scan(x, robot_id, origin=(0.0, 0.3 if robot_id == "m2" else 0.0, 0.5))
        self.sent[robot_id] = self.sent.get(robot_id, 0) + 1

    def test_follows_deltas_and_resyncs_on_a_new_epoch(self):
        self.sent = {}
        mirror = octomap_rt.MapMirror(self.client)
        stale = octomap_rt.MapMirror(self.client, resync=False)
        mirror.sync()
        stale.sync()
        for k in range(6):
            self.publish(2.0 + 0.5 * k, "m1" if k % 2 == 0 else "m2")
            mirror.spin(0.3)
            stale.spin(0.05)
        snap = self.follow([mirror, stale])
        _, server_leaves = read_bt_leaves(snap.data)
        self.assertGreater(len(server_leaves), 100)
        self.assertEqual(canonical_leaves(mirror.leaves), canonical_leaves(server_leaves))
        self.assertEqual((mirror.version, mirror.epoch), (snap.snapshot_id, snap.map_epoch))
        self.assertGreater(mirror.stats.deltas_applied, 0)
        self.assertEqual(mirror.stats.snapshots, 1, "followed by deltas alone")

        # A reset starts a new epoch: the mirror sees it and resyncs.
        epoch = mirror.epoch
        ack = self.client.reset_map(TOKEN)
        self.assertNotEqual(ack.map_epoch, epoch)
        self.publish(3.5, "m1")
        snap = self.follow([mirror, stale])
        self.assertEqual(snap.map_epoch, ack.map_epoch)
        _, server_leaves = read_bt_leaves(snap.data)
        self.assertGreater(len(server_leaves), 10)
        self.assertEqual((mirror.version, mirror.epoch), (snap.snapshot_id, snap.map_epoch))
        self.assertEqual(canonical_leaves(mirror.leaves), canonical_leaves(server_leaves))
        self.assertGreaterEqual(mirror.stats.epoch_changes, 1)
        self.assertEqual(mirror.stats.snapshots, 2)
        # Without the resync the old map's voxels stay: the epoch rule is what made it equal.
        self.assertGreaterEqual(stale.stats.epoch_changes, 1)
        self.assertNotEqual(canonical_leaves(stale.leaves), canonical_leaves(server_leaves))
        mirror.close()
        stale.close()


def _varint(v: int) -> bytes:
    out = bytearray()
    while v >= 0x80:
        out.append((v & 0x7F) | 0x80)
        v >>= 7
    out.append(v)
    return bytes(out)


def _delta(seq, from_version, to_version, classes, epoch):
    """A map_delta_t's bytes as the server encodes one (protocol/delta_codec.cpp), class mode."""
    import zstandard
    d = octomap_rt.map_delta_t()
    d.delta_seq, d.from_version, d.to_version, d.part_index, d.num_parts = seq, from_version, to_version, 0, 1
    d.mode, d.compression, d.map_epoch, d.resolution = 1, octomap_rt.map_chunk_t.COMPRESSION_ZSTD, epoch, 0.1
    keys, raw, prev = sorted(classes), b"", 0
    for k in keys:
        raw, prev = raw + _varint(k - prev), k
    raw += bytes(classes[k] for k in keys)
    d.num_voxels, d.uncompressed_size = len(keys), len(raw)
    d.data = zstandard.ZstdCompressor().compress(raw)
    d.data_size, d.server_id = len(d.data), "test"
    return d.encode()


class _Transport:
    """Messages queued by the test, handed to the subscribers by handle()."""
    url = "test"

    def __init__(self):
        self.subs, self.queue = {}, []

    def subscribe(self, channel, handler):
        self.subs[len(self.subs)] = (channel, handler)
        return len(self.subs) - 1

    def unsubscribe(self, sub):
        self.subs.pop(sub, None)

    def handle(self, _timeout_s):
        while self.queue:
            channel, data = self.queue.pop(0)
            for c, h in list(self.subs.values()):
                if c == channel:
                    h(channel, data)


class _Server:
    """What the mirror asks of a MapClient: its channels, transport and an (empty) snapshot."""
    EMPTY_BT = b"# Octomap OcTree binary file\nid OcTree\nsize 0\nres 0.1\ndata\n"

    def __init__(self):
        self.channels, self.transport = octomap_rt.Channels(""), _Transport()
        self.epoch, self.version, self.fetches = 7, 0, 0

    def fetch_snapshot(self, fmt, timeout_s=30.0):
        self.fetches += 1
        return octomap_rt.Snapshot(self.version, 0, fmt, self.EMPTY_BT, 0, 1, 1, 0.0, self.epoch)

    def send(self, *delta_args):
        self.transport.queue.append((self.channels.map_delta, _delta(*delta_args)))


class MirrorRulesTest(unittest.TestCase):
    """PROTOCOL.md's resync rules on hand-made deltas: in order they are applied; a gap in
    delta_seq and a delta of another epoch each make the mirror fetch a fresh snapshot."""

    def test_in_order_then_a_gap_then_a_new_epoch(self):
        key = lambda x, y, z: (x << 32) | (y << 16) | z  # noqa: E731
        server = _Server()
        info = octomap_rt.map_info_t()
        info.delta_seq, info.map_epoch = -1, 7
        server.transport.queue.append((server.channels.map_info, info.encode()))
        mirror = octomap_rt.MapMirror(server)
        mirror.sync()
        server.send(0, 0, 1, {key(1, 2, 3): 2, key(1, 2, 4): 1}, 7)
        server.send(1, 1, 2, {key(1, 2, 3): 1}, 7)
        mirror.spin(0.05)
        self.assertEqual(mirror.version, 2)
        self.assertEqual(mirror.leaves, {(16, 1, 2, 3): False, (16, 1, 2, 4): False})
        self.assertEqual(server.fetches, 1)
        server.version = 5
        server.send(3, 3, 4, {key(9, 9, 9): 2}, 7)  # delta 2 was lost
        mirror.spin(0.05)
        self.assertEqual((mirror.stats.gaps, server.fetches, mirror.version), (1, 2, 5))
        server.epoch, server.version = 8, 6
        server.send(0, 5, 6, {key(1, 1, 1): 2}, 8)  # a reset: ids of another history
        mirror.spin(0.05)
        self.assertEqual((mirror.epoch, mirror.stats.epoch_changes, server.fetches), (8, 1, 3))


class LeafAlgebraTest(unittest.TestCase):
    def test_a_voxel_set_in_a_pruned_leaf_splits_it(self):
        from octomap_rt.map_mirror import set_voxel
        leaves = {(14, 0, 0, 0): False}  # 4 x 4 x 4 free voxels as one leaf
        set_voxel(leaves, (1 << 32) | (2 << 16) | 3, True)
        self.assertEqual(sum(1 for v in leaves.values() if v), 1)
        self.assertEqual(len(leaves), 1 + 7 + 7)
        volume = sum(8 ** (16 - n[0]) for n in leaves)
        self.assertEqual(volume, 64)
        set_voxel(leaves, (1 << 32) | (2 << 16) | 3, False)
        self.assertEqual(canonical_leaves(leaves), {(14, 0, 0, 0): False})
