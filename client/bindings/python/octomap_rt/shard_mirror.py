"""ShardMirror: every shard's deltas followed in one mirror, as the C++ client's ShardMirror
(client/shard_client/shard_mirror.h; docs/PROTOCOL.md "Shards"). One MapMirror per shard of the
announced set (a ShardClient's), each on its shard's own namespace, so each keeps its shard's
epoch, map state id and delta_seq chain and resyncs alone: a gap or a new epoch of shard 2
fetches shard 2's snapshot only. The shards' regions are disjoint, so the one map's leaves are
the union of the shards' leaves.

Every shard's map_info_t (1 Hz) announces the set again: one of another set, or of another index
than its namespace says, is refused and counted, and does not count as hearing from that shard.
A shard never fetched is missing; one without a map_info_t for `late_after_s` is late. Both are
said in words (`shortfall`), and a merged map without every shard is partial."""

import time
from dataclasses import dataclass, field
from typing import Dict

from ._types import map_info_t
from .map_client import ServerTimeout
from .map_mirror import MapMirror
from .shards import ShardSet, ShardSetError
from .snapshot_fetch import FetchError


@dataclass
class MergedMirror:
    leaves: dict                                           # (depth, kx, ky, kz) -> occupied, every synced shard's
    missing: Dict[int, str] = field(default_factory=dict)  # shard index -> why it has no snapshot
    late: Dict[int, float] = field(default_factory=dict)   # shard index -> seconds since its last map_info_t
    shortfall: str = ""                                    # both in words; "" when every shard is in and fresh

    @property
    def partial(self) -> bool:
        return bool(self.missing)


class ShardMirror:
    """Follows every shard of `shards` (a ShardClient). sync() fetches the snapshots not held yet;
    spin(seconds) applies every shard's deltas and resyncs a shard on its gap or new epoch; a
    shard whose fetch failed is tried again after `retry_s`."""

    def __init__(self, shards, late_after_s: float = 3.0, retry_s: float = 3.0, fetch_timeout_s: float = 30.0,
                 occupied_above: float = 0.0):
        self.shards = shards
        self.late_after_s, self.retry_s = late_after_s, retry_s
        self.mirrors = [MapMirror(c, fetch_timeout_s=fetch_timeout_s, occupied_above=occupied_above)
                        for c in shards.shards]
        n = len(self.mirrors)
        self.errors = {i: "no snapshot fetched yet" for i in range(n)}
        self.last_info = {}          # index -> time.monotonic() of its last map_info_t of the set
        self.refused_infos = [0] * n
        self._retry_after = [0.0] * n
        t = shards.transport
        self._subs = [t.subscribe(c.channels.map_info, self._info_handler(i)) for i, c in enumerate(shards.shards)]

    def _info_handler(self, index):
        def take(_channel, data):
            try:
                info = map_info_t.decode(data)
                heard = ShardSet.of_status(info)
            except (ValueError, IndexError, ShardSetError):
                self.refused_infos[index] += 1
                return
            if heard != self.shards.set or info.shard_index != index:
                self.refused_infos[index] += 1
                return
            self.last_info[index] = time.monotonic()
        return take

    def close(self) -> None:
        for m in self.mirrors:
            m.close()
        for s in self._subs:
            self.shards.transport.unsubscribe(s)
        self._subs = []

    def _try_sync(self, i: int) -> None:
        try:
            self.mirrors[i].sync()
            self.errors.pop(i, None)
        except (FetchError, ServerTimeout, TimeoutError) as e:
            self.errors[i] = str(e) or type(e).__name__
            self._retry_after[i] = time.monotonic() + self.retry_s

    def sync(self) -> None:
        """Fetches the snapshot of every shard not synced; one that fails is missing, the rest go on."""
        for i, m in enumerate(self.mirrors):
            if not m.synced:
                self._try_sync(i)

    def spin(self, seconds: float) -> None:
        """Every shard's deltas for `seconds` (one transport carries them all)."""
        end = time.monotonic() + seconds
        while True:
            for i, m in enumerate(self.mirrors):
                if m.needs_sync and time.monotonic() >= self._retry_after[i]:
                    self._try_sync(i)
            left = end - time.monotonic()
            if left <= 0:
                return
            self.shards.transport.handle(min(0.05, left))

    def merged(self) -> MergedMirror:
        """The one map's leaves (the union of the synced shards'), with what is missing or late."""
        now, count = time.monotonic(), len(self.mirrors)
        out = MergedMirror({})
        words = []
        for i, m in enumerate(self.mirrors):
            if not m.synced:
                out.missing[i] = self.errors.get(i, "no snapshot")
                words.append(f"shard {i} of {count} missing: {out.missing[i]}")
                continue
            out.leaves.update(m.leaves)
            if i in self.errors:  # holds an older snapshot's map: its resync failed
                words.append(f"shard {i} of {count} behind (resync failed: {self.errors[i]})")
            heard = self.last_info.get(i)
            if heard is None or now - heard > self.late_after_s:
                out.late[i] = float("inf") if heard is None else now - heard
                words.append(f"shard {i} of {count} late (no map info heard)" if heard is None else
                             f"shard {i} of {count} late (no map info for {now - heard:.1f} s)")
        out.shortfall = "; ".join(words)
        return out
