"""Occupancy queries to octomap-rt-server (docs/PROTOCOL.md, query section): points, rays,
boxes and the 2D grid, numpy in and out. Each request is one datagram-sized message on its
channel; the answer comes on the client's reply channel, matched by request_id. udpm is
lossy, so a request unanswered within `retry_after_s` is sent again (a new request_id)."""

import time
from typing import Optional

from ._types import (box_query_t, box_reply_t, grid_query_t, grid_t, occupancy_query_t,
                     occupancy_reply_t, ray_query_t, ray_reply_t)

from .channels import Channels
# Per message (one 60 KB datagram).
from .protocol_table import MAX_QUERY_BOXES as MAX_BOXES
from .protocol_table import MAX_QUERY_POINTS as MAX_POINTS
from .protocol_table import MAX_QUERY_RAYS as MAX_RAYS

UNKNOWN, FREE, OCCUPIED = occupancy_reply_t.OCC_UNKNOWN, occupancy_reply_t.OCC_FREE, occupancy_reply_t.OCC_OCCUPIED


class QueryError(RuntimeError):
    """The server refused or did not answer (status and its reason in the message)."""


class Wait:
    """What a query waits for on the server before it is answered (docs/PROTOCOL.md, "Waiting
    for a map state"): the map state `min_snapshot_id` (an edit's ack.snapshot_id) and/or the
    scan `seq` of robot `robot_id` applied, for at most `timeout_s` there (0..30 s; then the
    reply is NOT_READY, raised as QueryError). `epoch` (an ack's map_epoch; 0: any): a state id
    counts only in its epoch, so a reply of another epoch means the map's history forked since
    (a reset, a restart after a crash) and is raised as QueryError: the write may be gone."""

    def __init__(self, min_snapshot_id: int = 0, robot_id: str = "", seq: int = -1, epoch: int = 0,
                 timeout_s: float = 5.0):
        self.min_snapshot_id, self.robot_id, self.seq, self.epoch = min_snapshot_id, robot_id, seq, epoch
        self.timeout_s = timeout_s

    def waits(self) -> bool:
        return self.min_snapshot_id > 0 or bool(self.robot_id)

_REPLY_BUSY = occupancy_reply_t.REPLY_BUSY  # every reply type's status 3


class QueryChannel:
    """Sends a query and collects the reply messages with its request_id. `wait`, when set,
    is what every query waits for (read-your-writes: MapClient keeps it at the client's own
    latest scan and edit)."""

    def __init__(self, transport, client_id: str, timeout_s: float = 10.0, retry_after_s: float = 1.0,
                 channels: Optional[Channels] = None):
        self.transport = transport
        self.client_id = client_id
        self.channels = channels or Channels()
        self.reply_channel = self.channels.reply_channel(self.channels.query_reply_prefix, client_id)
        self.timeout_s = timeout_s
        self.retry_after_s = retry_after_s
        self._next_id = int(time.time() * 1000) * 1000
        self.wait: Optional[Wait] = None
        self.busy_retries = 0  # requests asked again after a BUSY reply

    def _stamp(self, msg, min_snapshot_id: int) -> None:
        msg.utime = int(time.time() * 1e6)
        self._next_id += 1
        msg.request_id = self._next_id
        w = self.wait if self.wait is not None and self.wait.waits() else None
        if w is not None:
            min_snapshot_id = max(min_snapshot_id, w.min_snapshot_id)
        # The map version to wait for; the field is named min_snapshot_id (or min_map_version).
        for name in ("min_snapshot_id", "min_map_version"):
            if name in msg.__slots__:
                setattr(msg, name, min_snapshot_id)
        msg.wait_robot_id = w.robot_id if w is not None else ""
        msg.wait_seq = w.seq if w is not None and w.robot_id else -1
        msg.wait_timeout_ms = int(min(30.0, max(0.0, w.timeout_s)) * 1000) if w is not None else 0
        msg.client_id = self.client_id
        msg.reply_channel = self.reply_channel

    def ask(self, channel: str, msg, reply_type, min_snapshot_id: int = 0, complete=lambda replies: True):
        """Publishes `msg` and returns the replies (a list) once `complete(replies)` holds."""
        replies, wanted = [], set()

        def take(_channel, data):
            try:
                r = reply_type.decode(data)
            except ValueError:
                return
            if r.request_id in wanted and (not replies or r.request_id == replies[0].request_id):
                replies.append(r)

        sub = self.transport.subscribe(self.reply_channel, take)
        w = self.wait if self.wait is not None and self.wait.waits() else None
        # A query that waits on the server is answered when its condition holds: not resent before.
        retry_after_s = self.retry_after_s + (min(30.0, w.timeout_s) if w is not None else 0.0)
        backoff_s = 0.02
        try:
            start = time.monotonic()
            while time.monotonic() - start < max(self.timeout_s, retry_after_s):
                self._stamp(msg, min_snapshot_id)
                wanted.add(msg.request_id)
                self.transport.publish(channel, msg.encode())
                sent = time.monotonic()
                while time.monotonic() - sent < retry_after_s and not (replies and complete(replies)):
                    self.transport.handle(0.05)
                if replies and complete(replies):
                    # BUSY: "this may fit another turn" (a full queue, or a region or grid cut by
                    # the time bound under the map lock): ask again, backing off, until the timeout.
                    if replies[0].status != _REPLY_BUSY or time.monotonic() + backoff_s - start >= self.timeout_s:
                        break
                    self.busy_retries += 1
                    time.sleep(backoff_s)
                    backoff_s = min(0.5, backoff_s * 2)
                replies.clear()
        finally:
            self.transport.unsubscribe(sub)
        if not replies:
            raise QueryError(f"no answer on {self.reply_channel} within {self.timeout_s} s: "
                             "is octomap-rt-server running with this LCM URL?")
        first = replies[0]
        if first.status != occupancy_reply_t.REPLY_OK:
            raise QueryError(f"query refused (status {first.status}): {first.error}")
        epoch = getattr(first, "map_epoch", 0)
        if w is not None and w.epoch and epoch and epoch != w.epoch:
            raise QueryError(f"the map's history forked since the write waited for (epoch {w.epoch:#x}, now "
                             f"{epoch:#x}: a reset, or a restart after a crash): the map may not hold it")
        return replies


def _float_list(array, np) -> list:
    return np.ascontiguousarray(array, dtype=np.float32).reshape(-1).tolist()


def query_points(q: QueryChannel, points, depth: int = 0, min_snapshot_id: int = 0):
    """(occupancy int8 array of UNKNOWN/FREE/OCCUPIED, probability float32 array, -1 where
    unknown) for an (N, 3) array of points in the map frame."""
    import numpy as np

    pts = np.asarray(points, dtype=np.float32).reshape(-1, 3)
    occ, prob = [], []
    for start in range(0, len(pts), MAX_POINTS):
        m = occupancy_query_t()
        m.depth = depth
        m.xyz = _float_list(pts[start:start + MAX_POINTS], np)
        m.num_xyz = len(m.xyz)
        r = q.ask(q.channels.query_points, m, occupancy_reply_t, min_snapshot_id)[0]
        occ.extend(r.occupancy)
        prob.extend(r.probability)
    return np.asarray(occ, dtype=np.int8), np.asarray(prob, dtype=np.float32)


def cast_rays(q: QueryChannel, origins, directions, max_range: float = -1.0, ignore_unknown: bool = False,
              min_snapshot_id: int = 0):
    """OcTree::castRay for each ray: (hit bool array, end_state int8 array, end points (N, 3)).
    `origins` may be one point for all rays."""
    import numpy as np

    dirs = np.asarray(directions, dtype=np.float32).reshape(-1, 3)
    orig = np.broadcast_to(np.asarray(origins, dtype=np.float32).reshape(-1, 3), dirs.shape)
    hit, state, ends = [], [], []
    for start in range(0, len(dirs), MAX_RAYS):
        m = ray_query_t()
        m.ignore_unknown = 1 if ignore_unknown else 0
        m.max_range = float(max_range)
        m.origin_xyz = _float_list(orig[start:start + MAX_RAYS], np)
        m.direction_xyz = _float_list(dirs[start:start + MAX_RAYS], np)
        m.num_xyz = len(m.origin_xyz)
        r = q.ask(q.channels.query_rays, m, ray_reply_t, min_snapshot_id)[0]
        hit.extend(r.hit)
        state.extend(r.end_state)
        ends.extend(r.end_xyz)
    return (np.asarray(hit, dtype=bool), np.asarray(state, dtype=np.int8),
            np.asarray(ends, dtype=np.float32).reshape(-1, 3))


def box_counts(q: QueryChannel, boxes, min_snapshot_id: int = 0):
    """Finest-voxel counts per box ((N, 6): min x y z, max x y z): a dict of int64 arrays
    'occupied', 'free', 'unknown'."""
    import numpy as np

    b = np.asarray(boxes, dtype=np.float64).reshape(-1, 6)
    out = {"occupied": [], "free": [], "unknown": []}
    for start in range(0, len(b), MAX_BOXES):
        m = box_query_t()
        m.mode = box_query_t.MODE_COUNTS
        m.boxes = b[start:start + MAX_BOXES].reshape(-1).tolist()
        m.num_values = len(m.boxes)
        r = q.ask(q.channels.query_boxes, m, box_reply_t, min_snapshot_id)[0]
        for key in out:
            out[key].extend(getattr(r, key))
    return {k: np.asarray(v, dtype=np.int64) for k, v in out.items()}


def grid(q: QueryChannel, z_min: float, z_max: float, cell_size: float = 0.0,
         window: Optional[tuple] = None, min_snapshot_id: int = 0):
    """The 2D grid of a z band: (cells, origin (x, y), cell size), cells an int8 array
    [row j, column i] of UNKNOWN/FREE/OCCUPIED, cell (i, j) at origin + (i, j) * cell size."""
    import numpy as np

    m = grid_query_t()
    m.z_min, m.z_max, m.cell_size = float(z_min), float(z_max), float(cell_size)
    m.use_window = 1 if window else 0
    (x0, y0), (x1, y1) = window if window else ((0.0, 0.0), (0.0, 0.0))
    m.window_min, m.window_max = [float(x0), float(y0)], [float(x1), float(y1)]
    parts = q.ask(q.channels.query_grid, m, grid_t, min_snapshot_id,
                  complete=lambda rs: len({r.chunk_index for r in rs}) >= rs[0].num_chunks)
    first = parts[0]
    cells = np.full((first.height, first.width), UNKNOWN, dtype=np.int8)
    for p in {r.chunk_index: r for r in parts}.values():
        rows = np.asarray(p.cells, dtype=np.int8).reshape(p.num_rows, first.width)
        cells[p.row_start:p.row_start + p.num_rows] = rows
    return cells, (first.origin_x, first.origin_y), first.cell_size
