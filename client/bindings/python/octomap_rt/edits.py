"""Map edits from Python (docs/PROTOCOL.md, "Map edits" and "Authenticated edits"): clear a box
to free or unknown, or reset the map. Each edit is signed with an HMAC-SHA256 of its canonical
bytes, keyed by the server's control token, so the token itself never goes on the network; a
fresh nonce and the current time let the server refuse replays and stale edits."""

import hashlib
import hmac
import secrets
import struct
import time

from ._types import map_edit_ack_t, map_edit_t
from .channels import Channels
from .protocol_table import MAP_EDIT_CHANNEL as EDIT_CHANNEL
from .queries import QueryError

_DOMAIN = b"octomap-rt map_edit_t v1\x00"


def _string(s: str) -> bytes:
    b = s.encode("utf-8")
    return struct.pack(">I", len(b)) + b


def edit_mac_input(edit: map_edit_t, channel: str = EDIT_CHANNEL) -> bytes:
    """The canonical bytes the MAC covers (big-endian, strings as uint32 length + bytes)."""
    return (_DOMAIN + _string(channel) +
            struct.pack(">qqqbb", edit.utime, edit.request_id, edit.nonce, edit.op, edit.flags) +
            struct.pack(">6d", *edit.box_min, *edit.box_max) + _string(edit.client_id) + _string(edit.reply_channel))


def edit_mac(edit: map_edit_t, token: str, channel: str = EDIT_CHANNEL) -> bytes:
    return hmac.new(token.encode("utf-8"), edit_mac_input(edit, channel), hashlib.sha256).digest()


def sign_edit(edit: map_edit_t, token: str, channel: str = EDIT_CHANNEL) -> None:
    """Sets edit.mac (lcm-gen's int8 array: signed values); call after every other field is set."""
    edit.mac = list(struct.unpack("32b", edit_mac(edit, token, channel)))


class MapEditor:
    """Sends signed edits and waits for their acks (matched by request_id). udpm is lossy: an
    edit unacknowledged within `retry_after_s` is sent again as a new edit (new request id,
    nonce and MAC; clears and resets give the same map when applied twice)."""

    def __init__(self, transport, client_id: str, token: str, timeout_s: float = 10.0, retry_after_s: float = 1.0,
                 channels: Channels = None):
        self.transport = transport
        self.client_id = client_id
        self.token = token
        self.channels = channels or Channels()
        self.edit_channel = self.channels.map_edit  # the MAC covers it: NS_ + the name in a namespace
        self.reply_channel = self.channels.reply_channel(self.channels.query_reply_prefix, client_id)
        self.timeout_s = timeout_s
        self.retry_after_s = retry_after_s
        self._next_id = int(time.time() * 1000) * 1000

    def new_edit(self, op: int, box=None, flags: int = 0) -> map_edit_t:
        e = map_edit_t()
        e.utime = int(time.time() * 1e6)
        self._next_id += 1
        e.request_id = self._next_id
        e.nonce = secrets.randbits(64) - (1 << 63)
        e.op, e.flags = op, flags
        lo, hi = (box[:3], box[3:]) if box is not None else ((0.0,) * 3, (0.0,) * 3)
        e.box_min, e.box_max = [float(v) for v in lo], [float(v) for v in hi]
        e.client_id, e.reply_channel = self.client_id, self.reply_channel
        sign_edit(e, self.token, self.edit_channel)
        return e

    def send(self, data: bytes, request_id: int, wait_s: float):
        """Publishes encoded edit bytes once; the ack with `request_id`, or None within wait_s."""
        got = []

        def take(_channel, raw):
            try:
                a = map_edit_ack_t.decode(raw)
            except ValueError:
                return
            if a.request_id == request_id:
                got.append(a)

        sub = self.transport.subscribe(self.reply_channel, take)
        try:
            self.transport.publish(self.edit_channel, data)
            end = time.monotonic() + wait_s
            while not got and time.monotonic() < end:
                self.transport.handle(0.05)
        finally:
            self.transport.unsubscribe(sub)
        return got[0] if got else None

    def edit(self, op: int, box=None, flags: int = 0) -> map_edit_ack_t:
        """Sends the edit until acked; raises QueryError when refused or unanswered."""
        start = time.monotonic()
        while time.monotonic() - start < self.timeout_s:
            e = self.new_edit(op, box, flags)
            ack = self.send(e.encode(), e.request_id, self.retry_after_s)
            if ack is None:
                continue
            if ack.status != 0:
                raise QueryError(f"edit refused (status {ack.status}): {ack.error}")
            return ack
        raise QueryError(f"no acknowledgement on {self.reply_channel} within {self.timeout_s} s: "
                         "is octomap-rt-server running with this LCM URL?")
