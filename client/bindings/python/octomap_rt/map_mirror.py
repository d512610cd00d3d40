"""MapMirror: a local copy of the server's map kept equal by its deltas (docs/PROTOCOL.md
"Resync"), as the C++ client's MapMirror (client/map_client/map_mirror.h) keeps it: one
snapshot, then every map_delta_t applied in delta_seq order. A missed delta (a gap in
delta_seq, a change set whose start was not seen, a map_info_t naming a delta never received)
or a delta or map_info_t of another epoch (a reset, a server that lost changes in a crash,
another map file: its state ids mean another map) makes it fetch a fresh snapshot and go on
from there with the deltas that came meanwhile. A server restarted cleanly keeps epoch and id
and numbers its deltas from 0 again: a change set that starts at the mirror's version goes on.

The mirror holds each voxel's class (free or occupied), as the C++ mirror does in the server's
default class mode: `leaves` maps (depth, kx, ky, kz) (a leaf's depth and smallest OctoMap key)
to True where occupied. Deltas in log-odds mode (server flag --delta-exact) are classed by
`occupied_above` (log-odds; OctoMap's default threshold 0.5 is 0)."""

import time
from collections import defaultdict
from dataclasses import dataclass

from ._types import map_chunk_t, map_delta_t, map_info_t
from .bt_reader import TREE_DEPTH, read_bt_leaves

_MAX_VOXELS_PER_PART = 1 << 20  # protocol/delta_codec.cpp's bound


class DeltaError(ValueError):
    """A delta part that does not decode (its changes are lost: the mirror resyncs)."""


@dataclass
class MirrorStats:
    snapshots: int = 0
    deltas_applied: int = 0
    deltas_skipped: int = 0
    gaps: int = 0
    bad_deltas: int = 0
    voxels_applied: int = 0
    epoch_changes: int = 0  # deltas or infos of another epoch seen (each a gap too)


def decode_delta_part(d: map_delta_t):
    """[(packed key x << 32 | y << 16 | z, value)] of one delta part: a class (map_delta_t.CLASS_*)
    or a log-odds float. Raises DeltaError where protocol/delta_codec.cpp's decoder throws."""
    import struct

    if d.mode not in (map_delta_t.MODE_CLASS, map_delta_t.MODE_LOG_ODDS):
        raise DeltaError(f"unknown delta mode {d.mode}")
    if not 0 <= d.num_voxels <= _MAX_VOXELS_PER_PART:
        raise DeltaError(f"voxel count {d.num_voxels} out of range")
    value_bytes = 4 if d.mode == map_delta_t.MODE_LOG_ODDS else 1
    if not 0 <= d.uncompressed_size <= d.num_voxels * (7 + value_bytes):
        raise DeltaError("payload size does not fit the voxel count")
    data = bytes(d.data)
    if d.compression == map_chunk_t.COMPRESSION_ZSTD:
        import zstandard  # Debian: python3-zstandard
        try:
            data = zstandard.ZstdDecompressor().decompress(data, max_output_size=d.uncompressed_size)
        except zstandard.ZstdError as e:
            raise DeltaError(f"zstd: {e}") from None
    elif d.compression != map_chunk_t.COMPRESSION_NONE:
        raise DeltaError(f"unknown compression {d.compression}")
    if len(data) != d.uncompressed_size:
        raise DeltaError("payload size mismatch")
    keys, pos, key = [], 0, 0
    for _ in range(d.num_voxels):
        gap, shift = 0, 0
        while True:
            if pos >= len(data) or shift > 63:
                raise DeltaError("bad varint")
            b = data[pos]
            pos += 1
            gap |= (b & 0x7F) << shift
            shift += 7
            if b < 0x80:
                break
        if keys and gap == 0:
            raise DeltaError("keys not ascending")
        key += gap
        if key >= 1 << 48:
            raise DeltaError("key out of range")
        keys.append(key)
    if len(data) - pos != d.num_voxels * value_bytes:
        raise DeltaError("values do not fit the voxel count")
    if d.mode == map_delta_t.MODE_LOG_ODDS:
        values = struct.unpack_from(f"<{d.num_voxels}f", data, pos)
    else:
        values = struct.unpack_from(f"{d.num_voxels}b", data, pos)
        if any(v not in (map_delta_t.CLASS_FREE, map_delta_t.CLASS_OCCUPIED) for v in values):
            raise DeltaError("a value that is not a class")
    return list(zip(keys, values))


def set_voxel(leaves: dict, packed_key: int, occupied: bool) -> None:
    """Gives the finest voxel `packed_key` its class in `leaves` (OctoMap's setNodeValue on it:
    a larger leaf around it is split down to it, its other parts keep their class)."""
    x, y, z = packed_key >> 32, (packed_key >> 16) & 0xFFFF, packed_key & 0xFFFF
    for depth in range(TREE_DEPTH, -1, -1):
        mask = ~((1 << (TREE_DEPTH - depth)) - 1)
        node = (depth, x & mask, y & mask, z & mask)
        was = leaves.get(node)
        if was is not None:
            break
    else:  # unknown until now
        leaves[(TREE_DEPTH, x, y, z)] = occupied
        return
    if depth == TREE_DEPTH or was == occupied:
        leaves[node] = occupied
        return
    del leaves[node]
    for d in range(depth, TREE_DEPTH):  # split the leaf level by level along the voxel's path
        half = 1 << (TREE_DEPTH - d - 1)
        mask = ~((1 << (TREE_DEPTH - d)) - 1)
        bx, by, bz = x & mask, y & mask, z & mask
        on_path = (bool(x & half), bool(y & half), bool(z & half))
        for i in range(8):
            corner = (bool(i & 1), bool(i & 2), bool(i & 4))
            if corner != on_path:
                leaves[(d + 1, bx + half * corner[0], by + half * corner[1], bz + half * corner[2])] = was
    leaves[(TREE_DEPTH, x, y, z)] = occupied


def canonical_leaves(leaves: dict) -> dict:
    """The same classes with every 8 sibling leaves of one class merged into their parent, up
    to the root: one spelling of a map's classes (two trees of different pruning compare)."""
    out = dict(leaves)
    for depth in range(TREE_DEPTH, 0, -1):
        bit = 1 << (TREE_DEPTH - depth)
        groups = defaultdict(list)
        for node, value in out.items():
            if node[0] == depth:
                groups[(depth - 1, node[1] & ~bit, node[2] & ~bit, node[3] & ~bit)].append((node, value))
        for parent, children in groups.items():
            if len(children) == 8 and len({v for _, v in children}) == 1:
                for node, _ in children:
                    del out[node]
                out[parent] = children[0][1]
    return out


class MapMirror:
    """Follows the server of `client` (a MapClient). sync() fetches a snapshot; spin(seconds)
    applies deltas as they come and resyncs on a gap or a new epoch (resync=False only counts
    gaps)."""

    def __init__(self, client, resync: bool = True, fetch_timeout_s: float = 30.0, occupied_above: float = 0.0):
        self.client = client
        self.resync = resync
        self.fetch_timeout_s = fetch_timeout_s
        self.occupied_above = occupied_above
        self.leaves = {}
        self.version = -1  # map state id the mirror is at
        self.epoch = 0     # and its epoch
        self.stats = MirrorStats()
        self._synced = False
        self._set_open = False       # a change set's first parts applied, not yet its last
        self._last_seq = -1          # last delta applied or skipped as contained
        self._highest_seq = -1       # highest delta_seq received, or known to be in the snapshot
        self._latest_info_seq = -1   # delta_seq of the latest map_info_t
        self._info_seen = False
        self._started = False        # a change set applied from its first part since the snapshot
        self._syncing = False
        self._need_sync = False
        self._buffered = []
        t = client.transport
        self._subs = [t.subscribe(client.channels.map_delta, self._on_delta_bytes),
                      t.subscribe(client.channels.map_info, self._on_info_bytes)]

    @property
    def synced(self) -> bool:
        """A snapshot was fetched (leaves, version and epoch are the server's map at some point)."""
        return self._synced

    @property
    def needs_sync(self) -> bool:
        """No snapshot yet, or a gap or a new epoch was seen since: the next spin() fetches one."""
        return self._need_sync or not self._synced

    def close(self) -> None:
        for s in self._subs:
            self.client.transport.unsubscribe(s)
        self._subs = []

    def _on_delta_bytes(self, _channel, data):
        try:
            d = map_delta_t.decode(data)
        except (ValueError, IndexError):
            return
        self._highest_seq = max(self._highest_seq, d.delta_seq)
        if self._syncing or not self._synced:
            self._buffered.append(d)
            return
        self._process(d, buffered=False)

    # The server publishes a delta before any map_info_t naming its delta_seq, from one socket:
    # an info naming a delta_seq never received means that delta was lost.
    def _on_info_bytes(self, _channel, data):
        try:
            info = map_info_t.decode(data)
        except (ValueError, IndexError):
            return
        baseline = not self._info_seen
        self._info_seen = True
        self._latest_info_seq = info.delta_seq
        if info.delta_seq < self._highest_seq or baseline:
            self._highest_seq = info.delta_seq  # or the server started again
        if self._syncing or not self._synced or self._need_sync:
            return
        if info.map_epoch != self.epoch:  # the map's history forked since the snapshot
            self.stats.epoch_changes += 1
            self._gap()
            return
        if info.delta_seq <= self._highest_seq:
            return
        self._highest_seq = info.delta_seq
        self._gap()

    def sync(self) -> None:
        """A fresh snapshot, then the deltas that came meanwhile. Raises FetchError."""
        t = self.client.transport
        if not self._info_seen:  # 1 Hz; deltas sent before the latest info are in the snapshot
            deadline = time.monotonic() + 1.5
            while not self._info_seen and time.monotonic() < deadline:
                t.handle(0.05)
        sent_before = self._latest_info_seq
        self._syncing = True
        self._buffered = []
        try:
            snapshot = self.client.fetch_snapshot("bt", timeout_s=self.fetch_timeout_s)
        finally:
            self._syncing = False
        _, self.leaves = read_bt_leaves(snapshot.data)
        self._highest_seq = max(self._highest_seq, sent_before)
        self.version, self.epoch = snapshot.snapshot_id, snapshot.map_epoch
        self._synced = True
        self._started = self._set_open = self._need_sync = False
        self._last_seq = -1
        self.stats.snapshots += 1
        pending, self._buffered = sorted(self._buffered, key=lambda d: d.delta_seq), []
        for d in pending:
            if self._need_sync:
                break
            self._process(d, buffered=True)

    def spin(self, seconds: float) -> None:
        """Applies deltas for `seconds`, resyncing (when enabled) after a gap."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if self._need_sync or not self._synced:
                self.sync()
            self.client.transport.handle(min(0.05, max(0.0, end - time.monotonic())))

    def _gap(self) -> None:
        self.stats.gaps += 1
        if self.resync:
            self._need_sync = True

    def _process(self, d: map_delta_t, buffered: bool) -> None:
        if self._need_sync:
            return
        if d.map_epoch != self.epoch:
            if buffered:  # sent before the snapshot's history began: not part of it
                self.stats.deltas_skipped += 1
                return
            self.stats.epoch_changes += 1
            self._gap()
            return
        if not self._started:
            if d.to_version <= self.version:  # already in the snapshot
                self.stats.deltas_skipped += 1
                self._last_seq = d.delta_seq
                return
            continues = self._last_seq >= 0 and d.delta_seq == self._last_seq + 1
            if d.from_version > self.version or (d.part_index != 0 and not continues):
                self._gap()  # changes between the snapshot and this delta were not seen
                if not self.resync:
                    self._apply(d)
                return
            self._started = True
        elif d.delta_seq != self._last_seq + 1:
            # A server restarted from its clean save numbers its deltas from 0 again: a set that
            # starts at the mirror's complete version continues the chain whatever its delta_seq.
            chains = not self._set_open and d.part_index == 0 and d.from_version == self.version
            if not chains:
                self._gap()
                if self.resync:
                    return
        self._apply(d)

    def _apply(self, d: map_delta_t) -> None:
        try:
            changes = decode_delta_part(d)
        except DeltaError:
            self.stats.bad_deltas += 1
            self._last_seq = d.delta_seq
            self._gap()  # its changes are lost: as if it never came
            return
        log_odds = d.mode == map_delta_t.MODE_LOG_ODDS
        for key, value in changes:
            set_voxel(self.leaves, key,
                      value > self.occupied_above if log_odds else value == map_delta_t.CLASS_OCCUPIED)
        self._last_seq = d.delta_seq
        complete = d.part_index == d.num_parts - 1
        if complete:
            self.version = max(self.version, d.to_version)
        self._set_open = not complete
        self.stats.deltas_applied += 1
        self.stats.voxels_applied += len(changes)
