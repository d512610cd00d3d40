"""The protocol's channels in a namespace, by protocol/channels.h's rule: with namespace NS every
channel is NS_ + its name (reply channels included); without one the names are today's. The
namespace comes from the argument, else $OCTOMAP_RT_NAMESPACE."""

import os
import re
from typing import Optional

from . import protocol_table as table

_NAMESPACE = re.compile(r"[A-Za-z0-9_]*")


def namespace_from(requested: Optional[str] = None) -> str:
    """`requested` if given, else $OCTOMAP_RT_NAMESPACE, else "" (today's names)."""
    return requested or os.environ.get(table.NAMESPACE_ENV) or ""


def in_namespace(ns: str, name: str) -> str:
    return f"{ns}_{name}" if ns else name


def _checked(name: str, room: int = 0) -> str:
    if len(name) + room > table.MAX_CHANNEL_LENGTH:
        raise ValueError(f"channel {name}: {len(name) + room} characters, LCM takes at most "
                         f"{table.MAX_CHANNEL_LENGTH}")
    return name


class Channels:
    """Every channel of one namespace (prefixes end in '_': a robot or client id follows)."""

    def __init__(self, namespace: Optional[str] = None):
        ns = namespace_from(namespace)
        if not _NAMESPACE.fullmatch(ns):
            raise ValueError(f"namespace {ns!r} may hold only letters, digits and '_'")
        self.ns = ns
        fixed = lambda base: _checked(in_namespace(ns, base))  # noqa: E731
        prefix = lambda base: _checked(in_namespace(ns, base), room=1)  # noqa: E731
        self.scan_prefix = prefix(table.SCAN_CHANNEL_PREFIX)
        self.status = fixed(table.STATUS_CHANNEL)
        self.map_request = fixed(table.MAP_REQUEST_CHANNEL)
        self.map_info = fixed(table.MAP_INFO_CHANNEL)
        self.map_delta = fixed(table.MAP_DELTA_CHANNEL)
        self.map_reply_prefix = prefix(table.MAP_REPLY_PREFIX)
        self.query_points = fixed(table.QUERY_CHANNEL)
        self.query_rays = fixed(table.QUERY_RAYS_CHANNEL)
        self.query_boxes = fixed(table.QUERY_BOXES_CHANNEL)
        self.query_grid = fixed(table.QUERY_GRID_CHANNEL)
        self.query_distance = fixed(table.QUERY_DISTANCE_CHANNEL)
        self.map_edit = fixed(table.MAP_EDIT_CHANNEL)
        self.query_reply_prefix = prefix(table.QUERY_REPLY_PREFIX)
        self.grid = fixed(table.GRID_CHANNEL)
        self.octomap_raw = fixed(table.OCTOMAP_RAW_CHANNEL)

    def reply_channel(self, prefix: str, client_id: str) -> str:
        """`prefix` + the client id as channels carry it (upper case, '-' as '_'), checked."""
        return _checked(prefix + client_id.upper().replace("-", "_"))
