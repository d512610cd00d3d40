"""Map edits from Python against a real octomap-rt-server in a network namespace, signed with
Python's hmac: a good edit applied (the box's known voxels free, its unknown space kept), a
forged, a replayed and a stale edit refused with their reasons, all counted for the client;
and the MAC of docs/PROTOCOL.md's test vector."""

import unittest

import octomap_rt
from octomap_rt import edits
from server_fixture import ServerTestCase

TOKEN = "correct horse battery staple"
Edit = octomap_rt.map_edit_t


class EditMacTest(unittest.TestCase):
    def test_the_protocols_test_vector(self):
        e = Edit()
        e.utime, e.request_id, e.nonce, e.op, e.flags = 1700000000000000, 42, 0x0123456789abcdef, 1, 1
        e.box_min, e.box_max = [-1.5, -2.0, 0.0], [3.25, 4.0, 2.5]
        e.client_id, e.reply_channel = "op-laptop", "OCTOMAP_RT_QUERY_REPLY_op-laptop"
        self.assertEqual(len(edits.edit_mac_input(e)), 171)
        self.assertEqual(edits.edit_mac(e, TOKEN).hex(),
                         "43c438d9f28edc9bfd49387db5cc06d0920214256168c2abff07736c474282b9")
        edits.sign_edit(e, TOKEN)
        self.assertEqual(list(Edit.decode(e.encode()).mac), list(e.mac))  # lcm-gen's int8 array takes it


class EditsTest(ServerTestCase):
    server_args = ["--control-token", TOKEN]

    def client_stats(self, accept):
        """This client's query_client_stats_t from the first status that `accept`s it (a status
        composed just before the last answer was counted may still be on its way)."""
        def mine(s):
            return next((c for c in s.query_clients if c.client_id == self.client.client_id), None)

        s = self.client.wait_for("OCTOMAP_RT_STATUS", octomap_rt.server_status_t.decode, timeout_s=10,
                                 accept=lambda s: mine(s) is not None and accept(mine(s)))
        return mine(s)

    def test_good_forged_replayed_and_stale_edits(self):
        self.publish_wall(4.0, "py5")
        # Beyond the wall (x > 4.1) the sensor saw nothing: unknown, and it stays so.
        box = [3.0, -1.05, 0.45, 6.0, 1.05, 1.55]
        was = self.client.box([box])
        self.assertGreater(int(was["occupied"][0]), 0)
        self.assertGreater(int(was["unknown"][0]), 0)
        ack = self.client.clear_box(box, TOKEN)
        now = self.client.box([box], min_snapshot_id=ack.snapshot_id)
        self.assertEqual(int(now["occupied"][0]), 0)
        self.assertEqual(int(now["unknown"][0]), int(was["unknown"][0]))
        self.assertEqual(int(now["free"][0]), int(was["free"][0]) + int(was["occupied"][0]))

        # Forged: signed with another token.
        with self.assertRaises(octomap_rt.QueryError) as refused:
            self.client.editor("not the servers token at all").edit(Edit.OP_RESET)
        self.assertIn("bad MAC", str(refused.exception))

        # Replayed: the same bytes twice (what anyone who saw the first could send).
        editor = self.client.editor(TOKEN)
        e = editor.new_edit(Edit.OP_CLEAR_TO_UNKNOWN, box)
        data = e.encode()
        first = editor.send(data, e.request_id, 10.0)
        self.assertEqual(first.status, 0, first.error)
        again = editor.send(data, e.request_id, 10.0)
        self.assertEqual(again.status, octomap_rt.occupancy_reply_t.REPLY_REFUSED)
        self.assertIn("replayed", again.error)

        # Stale: correctly signed, but two minutes old (the server's window is 30 s).
        e = editor.new_edit(Edit.OP_RESET)
        e.utime -= 120 * 1000000
        edits.sign_edit(e, TOKEN)
        stale = editor.send(e.encode(), e.request_id, 10.0)
        self.assertEqual(stale.status, octomap_rt.occupancy_reply_t.REPLY_REFUSED)
        self.assertIn("stale", stale.error)
        # The map still holds the wall's cleared box, not a reset: a box query sees free space.
        self.assertGreater(int(self.client.box([[-1.0, -1.0, 0.45, 3.0, 1.0, 1.55]])["free"][0]), 0)

        # Every edit counted for this client: received = applied + refused (+ its box queries).
        c = self.client_stats(lambda c: c.edits_applied + c.edits_refused == 5)
        self.assertEqual(c.edits_applied, 2)
        self.assertEqual(c.edits_refused, 3)
        self.assertEqual(c.received, c.answered + c.edits_applied + c.edits_refused)

    def test_read_your_writes(self):
        """A client with read_your_writes sees its own scan and edit in the next query, without
        waiting by hand (no status polling, no min_snapshot_id), and is told when the map's
        history forked since its edit."""
        import numpy as np

        with octomap_rt.MapClient(self.url, read_your_writes=True) as c:
            wall = np.array([[7.0, y, z] for y in np.linspace(-1, 1, 21) for z in np.linspace(0, 1, 11)])
            c.publish_scan(wall, robot_id="pyrw", origin=(0.0, 0.0, 0.5))
            occ, _ = c.query_points(wall + [0.0, 0.0, 0.5])  # at once: the server waits for the scan
            self.assertTrue((occ == octomap_rt.OCCUPIED).all())
            box = [6.95, -1.05, 0.45, 7.05, 1.05, 1.55]
            ack = c.clear_box(box, TOKEN)
            self.assertEqual((c.written.min_snapshot_id, c.written.epoch), (ack.snapshot_id, ack.map_epoch))
            self.assertEqual(int(c.box([box])["occupied"][0]), 0)
            # A reply from another history than the edit's (here: the epoch the client holds is not
            # the server's) is refused, not taken for a map that holds the edit.
            c.written.epoch ^= 1
            with self.assertRaises(octomap_rt.QueryError) as forked:
                c.box([box])
            self.assertIn("history forked", str(forked.exception))


if __name__ == "__main__":
    unittest.main()
