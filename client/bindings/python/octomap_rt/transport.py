"""The transport MapClient talks through: LCM's own Python module where it is installed,
else the standard-library udpm transport (Debian bookworm ships no Python binding of LCM)."""

from typing import Callable, Optional

from .lcm_url import default_url

Handler = Callable[[str, bytes], None]


class _LcmModuleTransport:
    """`import lcm` behind the same four calls as UdpmTransport."""

    def __init__(self, lcm_module, url: str):
        self.url = url
        self._lcm = lcm_module.LCM(url)
        self._subs = {}

    def publish(self, channel: str, payload: bytes) -> None:
        self._lcm.publish(channel, bytes(payload))

    def subscribe(self, channel_regex: str, handler: Handler) -> int:
        sub = self._lcm.subscribe(channel_regex, handler)
        self._subs[id(sub)] = sub
        return id(sub)

    def unsubscribe(self, sub_id: int) -> None:
        self._lcm.unsubscribe(self._subs.pop(sub_id))

    def handle(self, timeout_s: Optional[float] = None) -> int:
        if timeout_s is None:
            self._lcm.handle()
            return 1
        return self._lcm.handle_timeout(max(0, int(timeout_s * 1000)))

    def fileno(self) -> int:
        return self._lcm.fileno()

    def close(self) -> None:
        self._lcm = None


def open_transport(url: Optional[str] = None, prefer_lcm_module: bool = True):
    """A transport on `url` (default: $LCM_DEFAULT_URL, else the host-local udpm URL)."""
    url = default_url(url)
    if prefer_lcm_module:
        try:
            import lcm  # noqa: F401  (LCM's own binding, where installed)
            return _LcmModuleTransport(lcm, url)
        except ImportError:
            pass
    from .udpm import UdpmTransport
    return UdpmTransport(url)
