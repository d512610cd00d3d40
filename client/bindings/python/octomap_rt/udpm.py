"""LCM's UDP multicast transport in the standard library (LCM 1.3's wire format).

A message is one datagram when channel + NUL + payload fit 65499 bytes ("LC02" header:
magic, sequence number), else fragments of at most 65487 bytes ("LC03" header: magic,
sequence number, payload size, offset, fragment number, fragment count; the first fragment
starts with the channel and its NUL). All integers are big-endian. Receivers reassemble by
(sender, sequence number); a message with a lost fragment is lost, as in LCM.
"""

import re
import select
import socket
import struct
import time
from typing import Callable, Dict, List, Optional, Tuple

from .lcm_url import UdpmUrl, parse_udpm_url
from .protocol_table import MAX_CHANNEL_LENGTH

MAGIC_SHORT = 0x4C433032  # "LC02"
MAGIC_LONG = 0x4C433033  # "LC03"
SHORT_MESSAGE_MAX_SIZE = 65499
FRAGMENT_MAX_PAYLOAD = 65487
_SHORT = struct.Struct(">II")
_LONG = struct.Struct(">IIIIHH")

Handler = Callable[[str, bytes], None]


class UdpmError(OSError):
    """The multicast socket could not be set up (the message says what to check)."""


class _Partial:
    """A fragmented message being reassembled."""

    def __init__(self, channel: Optional[str], size: int, count: int):
        self.channel = channel
        self.count = count
        self.data = bytearray(size)
        self.missing = set(range(count))
        self.started = time.monotonic()


def encode_datagrams(channel: str, payload: bytes, seqno: int) -> List[bytes]:
    """The datagrams LCM sends for one message."""
    name = channel.encode("ascii")
    if len(name) > MAX_CHANNEL_LENGTH:
        raise ValueError(f"channel name longer than {MAX_CHANNEL_LENGTH}: {channel!r}")
    if len(name) + 1 + len(payload) <= SHORT_MESSAGE_MAX_SIZE:
        return [_SHORT.pack(MAGIC_SHORT, seqno) + name + b"\0" + payload]
    first = FRAGMENT_MAX_PAYLOAD - len(name) - 1
    rest = len(payload) - first
    count = 1 + (rest + FRAGMENT_MAX_PAYLOAD - 1) // FRAGMENT_MAX_PAYLOAD
    if count > 65535:
        raise ValueError(f"message of {len(payload)} bytes needs more than 65535 fragments")
    out = [_LONG.pack(MAGIC_LONG, seqno, len(payload), 0, 0, count) + name + b"\0" + payload[:first]]
    offset = first
    for number in range(1, count):
        chunk = payload[offset:offset + FRAGMENT_MAX_PAYLOAD]
        out.append(_LONG.pack(MAGIC_LONG, seqno, len(payload), offset, number, count) + chunk)
        offset += len(chunk)
    return out


class UdpmTransport:
    """publish() / subscribe() / handle() over udpm, with LCM's semantics: channel patterns
    are anchored regular expressions; handlers run in handle(), on the caller's thread."""

    def __init__(self, url: str):
        self.url = url
        self.params: UdpmUrl = parse_udpm_url(url)
        self._seqno = 0
        self._subs: List[Tuple[int, "re.Pattern[str]", Handler]] = []
        self._next_id = 1
        self._partials: Dict[Tuple[Tuple[str, int], int], _Partial] = {}
        self._send = self._open_sender()
        self._recv = self._open_receiver()

    def _open_sender(self) -> socket.socket:
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, self.params.ttl)
        s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        return s

    def _open_receiver(self) -> socket.socket:
        p = self.params
        s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        if p.recv_buf_size:
            s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, p.recv_buf_size)
        s.bind(("", p.port))
        mreq = struct.pack("4s4s", socket.inet_aton(p.group), socket.inet_aton("0.0.0.0"))
        try:
            s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
        except OSError as e:
            s.close()
            raise UdpmError(
                f"cannot join multicast group {p.group}: {e}; on a single host run "
                "`ip link set lo multicast on; ip route add 224.0.0.0/4 dev lo`") from None
        return s

    def close(self) -> None:
        self._send.close()
        self._recv.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def fileno(self) -> int:
        return self._recv.fileno()

    def publish(self, channel: str, payload: bytes) -> None:
        for datagram in encode_datagrams(channel, bytes(payload), self._seqno):
            self._send.sendto(datagram, (self.params.group, self.params.port))
        self._seqno = (self._seqno + 1) & 0xFFFFFFFF

    def subscribe(self, channel_regex: str, handler: Handler) -> int:
        sub_id = self._next_id
        self._next_id += 1
        self._subs.append((sub_id, re.compile(channel_regex), handler))
        return sub_id

    def unsubscribe(self, sub_id: int) -> None:
        self._subs = [s for s in self._subs if s[0] != sub_id]

    def handle(self, timeout_s: Optional[float] = None) -> int:
        """Reads what arrived within `timeout_s` (None: wait for one datagram) and runs the
        handlers of every message completed; returns how many messages were dispatched."""
        ready, _, _ = select.select([self._recv], [], [], timeout_s)
        dispatched = 0
        while ready:
            datagram, sender = self._recv.recvfrom(65536)
            message = self._take(datagram, sender)
            if message:
                dispatched += self._dispatch(*message)
            ready, _, _ = select.select([self._recv], [], [], 0)
        return dispatched

    def _dispatch(self, channel: str, payload: bytes) -> int:
        n = 0
        for _, pattern, handler in list(self._subs):
            if pattern.fullmatch(channel):
                handler(channel, payload)
                n = 1
        return n

    def _take(self, datagram: bytes, sender) -> Optional[Tuple[str, bytes]]:
        if len(datagram) < _SHORT.size:
            return None
        magic, seqno = _SHORT.unpack_from(datagram)
        if magic == MAGIC_SHORT:
            end = datagram.find(b"\0", _SHORT.size)
            if end < 0:
                return None
            return datagram[_SHORT.size:end].decode("ascii", "replace"), datagram[end + 1:]
        if magic != MAGIC_LONG or len(datagram) < _LONG.size:
            return None
        return self._take_fragment(datagram, sender, seqno)

    def _take_fragment(self, datagram: bytes, sender, seqno: int) -> Optional[Tuple[str, bytes]]:
        _, _, size, offset, number, count = _LONG.unpack_from(datagram)
        body = datagram[_LONG.size:]
        key = (sender, seqno)
        part = self._partials.get(key)
        if part is None or len(part.data) != size or part.count != count:
            self._drop_stale()
            part = self._partials[key] = _Partial(None, size, count)
        if number == 0:
            end = body.find(b"\0")
            if end < 0:
                return None
            part.channel = body[:end].decode("ascii", "replace")
            body = body[end + 1:]
        if number not in part.missing or offset + len(body) > size:
            return None
        part.data[offset:offset + len(body)] = body
        part.missing.discard(number)
        if part.missing or part.channel is None:
            return None
        del self._partials[key]
        return part.channel, bytes(part.data)

    def _drop_stale(self, max_age_s: float = 10.0, max_partials: int = 64) -> None:
        """Forgets messages whose fragments stopped coming (LCM likewise bounds its store)."""
        now = time.monotonic()
        for key in [k for k, p in self._partials.items() if now - p.started > max_age_s]:
            del self._partials[key]
        while len(self._partials) >= max_partials:
            del self._partials[min(self._partials, key=lambda k: self._partials[k].started)]
