"""LCM URLs as LCM itself reads them: ``udpm://GROUP:PORT?ttl=N&recv_buf_size=B``."""

import os
import urllib.parse
from dataclasses import dataclass
from typing import Optional

# octomap-rt-server's default: host-local multicast (ttl=0: packets never leave the host).
from .protocol_table import DEFAULT_LCM_URL as HOST_LOCAL_URL


class LcmUrlError(ValueError):
    """The URL is not one this transport can use (and why)."""


@dataclass(frozen=True)
class UdpmUrl:
    group: str = "239.255.76.67"
    port: int = 7667
    ttl: int = 0
    recv_buf_size: Optional[int] = None  # bytes; None: the kernel's default


def default_url(requested: Optional[str] = None) -> str:
    """`requested` if given, else $LCM_DEFAULT_URL, else the host-local URL (as our C++ tools)."""
    return requested or os.environ.get("LCM_DEFAULT_URL") or HOST_LOCAL_URL


def parse_udpm_url(url: str) -> UdpmUrl:
    parts = urllib.parse.urlsplit(url)
    if parts.scheme != "udpm":
        raise LcmUrlError(f"only udpm:// URLs are supported without the lcm module, got {url!r}")
    group, _, port = parts.netloc.partition(":")
    options = dict(urllib.parse.parse_qsl(parts.query))
    unknown = set(options) - {"ttl", "recv_buf_size"}
    if unknown:
        raise LcmUrlError(f"unsupported option(s) {sorted(unknown)} in {url!r}")
    try:
        return UdpmUrl(
            group=group or UdpmUrl.group,
            port=int(port) if port else UdpmUrl.port,
            ttl=int(options.get("ttl", 0)),
            recv_buf_size=int(options["recv_buf_size"]) if "recv_buf_size" in options else None,
        )
    except ValueError as e:
        raise LcmUrlError(f"bad number in {url!r}: {e}") from None
