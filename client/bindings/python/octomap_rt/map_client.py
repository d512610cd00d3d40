"""MapClient: octomap-rt-server from Python (numpy in, numpy out)."""

import struct
import time
from typing import Optional, Sequence

from ._types import map_info_t, scan_t, server_status_t
from . import distance, edits, queries
from .bt_reader import BtMap, read_bt
from .snapshot_fetch import Snapshot, fetch_snapshot, new_client_id
from .transport import open_transport

from .channels import Channels


class ServerTimeout(TimeoutError):
    """No answer from octomap-rt-server within the time given (the message says to what)."""


def now_utime() -> int:
    return int(time.time() * 1e6)


class MapClient:
    """A client of one octomap-rt-server on one LCM URL.

    `url`: LCM URL (default $LCM_DEFAULT_URL, else the host-local udpm URL); add
    `recv_buf_size=` to receive multi-MB messages. `transport`: any object with publish,
    subscribe, unsubscribe and handle (default: open_transport(url)). `namespace`: the server's
    (its --namespace; default $OCTOMAP_RT_NAMESPACE, else none): every channel is NS_ + its name.
    `read_your_writes`: every query waits (up to `wait_timeout_s` on the server) until the map
    holds this client's latest scan (publish_scan) and its latest edit (clear_box, reset_map),
    and refuses an answer from another map history than the edit's (queries.Wait)."""

    def __init__(self, url: Optional[str] = None, transport=None, client_id: str = "",
                 namespace: Optional[str] = None, read_your_writes: bool = False, wait_timeout_s: float = 5.0):
        self.channels = Channels(namespace)
        self.transport = transport or open_transport(url)
        self.client_id = client_id or new_client_id()
        self.queries = queries.QueryChannel(self.transport, self.client_id, channels=self.channels)
        self._scan_seq = {}
        self.written = queries.Wait(timeout_s=wait_timeout_s)  # this client's latest scan and edit
        if read_your_writes:
            self.queries.wait = self.written

    def _edited(self, ack):
        """Notes an applied edit's map state (and its epoch) as the latest write."""
        self.written.min_snapshot_id, self.written.epoch = ack.snapshot_id, ack.map_epoch
        if ack.op == edits.map_edit_t.OP_RESET:
            self.written.robot_id, self.written.seq = "", -1  # the reset's state holds no earlier scan
        return ack

    def close(self) -> None:
        self.transport.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def wait_for(self, channel: str, decode, accept=lambda m: True, timeout_s: float = 5.0):
        """The first message on `channel` that decodes and that `accept` takes."""
        found = []
        seen = [0]  # messages that decoded but `accept` refused: said in the timeout's message

        def take(_channel, data):
            if found:
                return
            try:
                msg = decode(data)
            except (ValueError, struct.error):  # not this type (fingerprint, length): skipped
                return
            if accept(msg):
                found.append(msg)
            else:
                seen[0] += 1

        sub = self.transport.subscribe(channel, take)
        try:
            deadline = time.monotonic() + timeout_s
            while not found and time.monotonic() < deadline:
                self.transport.handle(min(0.1, max(0.0, deadline - time.monotonic())))
        finally:
            self.transport.unsubscribe(sub)
        if not found and seen[0]:
            raise ServerTimeout(f"{seen[0]} messages on {channel} within {timeout_s} s at {self.transport.url}, "
                                "none of them the one waited for")
        if not found:
            raise ServerTimeout(f"nothing on {channel} within {timeout_s} s at {self.transport.url}: "
                                "is octomap-rt-server running with this LCM URL?")
        return found[0]

    def status(self, timeout_s: float = 5.0) -> server_status_t:
        """The server's next status message (it sends one a second)."""
        return self.wait_for(self.channels.status, server_status_t.decode, timeout_s=timeout_s)

    def map_info(self, timeout_s: float = 5.0) -> map_info_t:
        """The server's next map_info_t (1 Hz and after each snapshot)."""
        return self.wait_for(self.channels.map_info, map_info_t.decode, timeout_s=timeout_s)

    def fetch_snapshot(self, format: str = "bt", timeout_s: float = 30.0, snapshot_id: int = -1) -> Snapshot:
        """The map as a .bt ("bt") or .ot ("ot") file's bytes in Snapshot.data: fresh
        (snapshot_id -1), the latest kept (0) or a kept one by id. Raises FetchError."""
        return fetch_snapshot(self.transport, format, timeout_s, snapshot_id, self.client_id, channels=self.channels)

    def fetch_map(self, timeout_s: float = 30.0) -> BtMap:
        """A fresh snapshot's occupied and free voxel centres as numpy arrays (read_bt)."""
        return read_bt(self.fetch_snapshot("bt", timeout_s).data)

    def query_points(self, points, depth: int = 0, min_snapshot_id: int = 0):
        """(occupancy, probability) arrays for (N, 3) points: queries.UNKNOWN/FREE/OCCUPIED and
        the node's occupancy probability (-1 where unknown)."""
        return queries.query_points(self.queries, points, depth, min_snapshot_id)

    def cast_rays(self, origins, directions, max_range: float = -1.0, ignore_unknown: bool = False,
                  min_snapshot_id: int = 0):
        """OcTree::castRay per ray on the server: (hit, end_state, end points (N, 3))."""
        return queries.cast_rays(self.queries, origins, directions, max_range, ignore_unknown, min_snapshot_id)

    def box(self, boxes, min_snapshot_id: int = 0):
        """Finest-voxel counts in boxes (N, 6): {'occupied', 'free', 'unknown'} arrays."""
        return queries.box_counts(self.queries, boxes, min_snapshot_id)

    def grid(self, z_min: float, z_max: float, cell_size: float = 0.0, window=None, min_snapshot_id: int = 0):
        """The 2D occupancy grid of a z band: (cells [row, column] int8, origin (x, y), cell size)."""
        return queries.grid(self.queries, z_min, z_max, cell_size, window, min_snapshot_id)

    def distance_points(self, points, max_distance: float = 2.0, unknown_occupied: bool = False,
                        gradient: bool = False, min_snapshot_id: int = 0):
        """(distance, gradient or None) of (N, 3) points' voxels to the nearest obstacle (octomap_rt.distance)."""
        return distance.distance_points(self.queries, points, max_distance, unknown_occupied, gradient, min_snapshot_id)

    def distance_box(self, box_min, box_max, max_distance: float = 2.0, unknown_occupied: bool = False,
                     gradient: bool = False, cell_voxels: int = 1, min_snapshot_id: int = 0):
        """The dense distance field of a box (octomap_rt.distance.distance_box)."""
        return distance.distance_box(self.queries, box_min, box_max, max_distance, unknown_occupied, gradient,
                                     cell_voxels, min_snapshot_id)

    def distance_path(self, vertices, max_distance: float = 2.0, unknown_occupied: bool = False,
                      min_snapshot_id: int = 0):
        """The clearance along a polyline: its lowest distance and where (octomap_rt.distance)."""
        return distance.distance_path(self.queries, vertices, max_distance, unknown_occupied, min_snapshot_id)

    def clear_box(self, box, token: str, to: str = "free", include_unknown: bool = False):
        """Clears the box (min x y z, max x y z) [m] on the server: to "free" (its known voxels;
        with include_unknown its never-seen ones too) or to "unknown". `token` is the server's
        --control-token: it signs the edit and is never sent. Returns the map_edit_ack_t (its
        snapshot_id: from that map state on the map holds the edit); raises QueryError if refused."""
        if to not in ("free", "unknown"):
            raise ValueError("to must be 'free' or 'unknown'")
        op = edits.map_edit_t.OP_CLEAR_TO_FREE if to == "free" else edits.map_edit_t.OP_CLEAR_TO_UNKNOWN
        flags = edits.map_edit_t.FLAG_INCLUDE_UNKNOWN if include_unknown else 0
        return self._edited(self.editor(token).edit(op, [float(v) for v in box], flags))

    def reset_map(self, token: str):
        """Empties the server's map (signed with `token`, as clear_box)."""
        return self._edited(self.editor(token).edit(edits.map_edit_t.OP_RESET))

    def editor(self, token: str) -> edits.MapEditor:
        """A MapEditor on this client's transport and id (for edits one by one, or raw bytes)."""
        return edits.MapEditor(self.transport, self.client_id, token, channels=self.channels)

    def publish_scan(self, points, robot_id: str, origin: Sequence[float] = (0.0, 0.0, 0.0),
                     orientation: Sequence[float] = (1.0, 0.0, 0.0, 0.0), points_in_map_frame: bool = False,
                     max_range: float = -1.0, seq: Optional[int] = None, utime: Optional[int] = None,
                     map_frame: str = "map") -> int:
        """Sends one scan as robot `robot_id` (channel [NS_]OCTOMAP_RT_SCAN_<ROBOT_ID>): `points` an
        (N, 3) array in the sensor frame (or the map frame), `origin` the sensor position and
        `orientation` its unit quaternion (w, x, y, z) in the map frame. Returns its seq
        (0, 1, 2, ... per robot unless given)."""
        import numpy as np

        xyz = np.ascontiguousarray(np.asarray(points, dtype=np.float32).reshape(-1, 3))
        msg = scan_t()
        msg.utime = now_utime() if utime is None else utime
        msg.seq = self._scan_seq.get(robot_id, 0) if seq is None else seq
        self._scan_seq[robot_id] = msg.seq + 1
        msg.sensor_position = [float(v) for v in origin]
        msg.sensor_orientation = [float(v) for v in orientation]
        msg.max_range = float(max_range)
        msg.points_frame = scan_t.POINTS_IN_MAP_FRAME if points_in_map_frame else scan_t.POINTS_IN_SENSOR_FRAME
        msg.xyz = xyz.reshape(-1).tolist()
        msg.num_xyz = len(msg.xyz)
        msg.robot_id = robot_id
        msg.map_frame = map_frame
        self.transport.publish(self.channels.scan_prefix + robot_id.upper(), msg.encode())
        self.written.robot_id, self.written.seq = robot_id, msg.seq
        return msg.seq
