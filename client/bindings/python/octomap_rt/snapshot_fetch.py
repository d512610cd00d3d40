"""Fetching a map snapshot from octomap-rt-server (docs/PROTOCOL.md): one map_request_t,
map_chunk_t answers of <= 60 KB on the client's reply channel, re-requests of the chunks
still missing after a silence, size and FNV-1a hash checked, zstd undone."""

import os
import random
import re
import time
from typing import Optional
from dataclasses import dataclass

from ._types import map_chunk_t, map_request_t

from .protocol_table import MAX_REQUESTED_CHUNKS
from .channels import Channels
FORMATS = {"bt": map_chunk_t.FORMAT_OCTOMAP_BINARY, "ot": map_chunk_t.FORMAT_OCTOMAP_FULL}


class FetchError(RuntimeError):
    """The snapshot did not come: no server, refused (with its reason), or corrupt."""


@dataclass
class Snapshot:
    snapshot_id: int
    num_scans: int
    format: str            # "bt" or "ot"
    data: bytes            # the .bt / .ot file's bytes
    compressed_size: int
    num_chunks: int
    requests: int
    seconds: float
    map_epoch: int = 0     # the history snapshot_id counts in (docs/PROTOCOL.md "Ids")


def fnv1a64(data: bytes) -> int:
    """protocol/map_protocol.h's blob_hash, as a signed 64-bit value like the message field."""
    h = 1469598103934665603
    for b in data:
        h = ((h ^ b) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return h - (1 << 64) if h >= 1 << 63 else h


def new_client_id() -> str:
    return f"py_{os.getpid()}_{random.randrange(1 << 30)}"


def _decompress(blob: bytes, compression: int, size: int) -> bytes:
    if compression == map_chunk_t.COMPRESSION_NONE:
        return blob
    if compression != map_chunk_t.COMPRESSION_ZSTD:
        raise FetchError(f"unknown compression {compression}")
    try:
        import zstandard
    except ImportError:
        raise FetchError("the snapshot is zstd-compressed: apt-get install python3-zstandard "
                         "(or run the server with --snapshot-zstd-level 0)") from None
    return zstandard.ZstdDecompressor().decompress(blob, max_output_size=size)


class _Assembly:
    def __init__(self):
        self.first = None
        self.chunks = {}
        self.error = ""
        self.last_arrival = time.monotonic()

    def take(self, chunk, request_ids) -> None:
        if chunk.request_id not in request_ids:
            return
        self.last_arrival = time.monotonic()
        if chunk.num_chunks == 0:
            self.error = chunk.error or "refused without a reason"
            return
        if self.first is None:
            self.first = chunk
        elif (chunk.snapshot_id, chunk.total_size, chunk.blob_hash) != (
                self.first.snapshot_id, self.first.total_size, self.first.blob_hash):
            return  # a chunk of another snapshot: not ours
        self.chunks[chunk.chunk_index] = chunk

    def missing(self):
        return [i for i in range(self.first.num_chunks) if i not in self.chunks] if self.first else None


def fetch_snapshot(transport, fmt: str = "bt", timeout_s: float = 30.0, snapshot_id: int = -1,
                   client_id: str = "", rerequest_after_s: float = 0.25,
                   first_answer_after_s: float = 3.0, channels: Optional[Channels] = None) -> Snapshot:
    """A snapshot: fresh (snapshot_id -1), the latest kept (0) or a kept one by id."""
    if fmt not in FORMATS:
        raise ValueError(f"format must be one of {sorted(FORMATS)}, got {fmt!r}")
    client_id = client_id or new_client_id()
    channels = channels or Channels()
    reply_channel = channels.reply_channel(channels.map_reply_prefix, client_id)
    assembly, request_ids = _Assembly(), set()

    def on_chunk(_channel, data):
        try:
            assembly.take(map_chunk_t.decode(data), request_ids)
        except ValueError:
            pass

    def request(snapshot, indices):
        req = map_request_t()
        req.utime = int(time.time() * 1e6)
        req.request_id = int(time.time() * 1e6) * 16 + len(request_ids)
        req.snapshot_id = snapshot
        req.format = FORMATS[fmt]
        req.chunk_indices = list(indices)
        req.num_chunk_indices = len(req.chunk_indices)
        req.client_id = client_id
        req.reply_channel = reply_channel
        request_ids.add(req.request_id)
        transport.publish(channels.map_request, req.encode())
        assembly.last_arrival = time.monotonic()

    sub = transport.subscribe(reply_channel, on_chunk)
    start = time.monotonic()
    try:
        request(snapshot_id, [])
        retry_at = None  # refused as busy: ask again then
        while time.monotonic() - start < timeout_s:
            transport.handle(0.05)
            if assembly.error.startswith("busy"):
                # Many clients at once: wait what the server names, stretched by a random
                # quarter to half so that clients refused together do not return together.
                match = re.search(r"retry after (\d+) ms", assembly.error)
                wait_s = min(5.0, int(match.group(1)) / 1000.0) if match else 0.2
                retry_at = time.monotonic() + wait_s * random.uniform(1.25, 1.5)
                assembly.error = ""
            if assembly.error:
                raise FetchError(f"the server refused the snapshot request: {assembly.error}")
            missing = assembly.missing()
            if missing == []:
                break
            if retry_at is not None:
                if time.monotonic() >= retry_at:
                    retry_at = None
                    if missing is None:
                        request(snapshot_id, [])
                    else:
                        request(assembly.first.snapshot_id, missing[:MAX_REQUESTED_CHUNKS])
                continue
            # Before the first chunk the server may be copying a big map or waiting for its
            # next fresh snapshot: ask again only after a longer silence.
            patience = rerequest_after_s if missing is not None else first_answer_after_s
            if time.monotonic() - assembly.last_arrival > patience:
                if missing is None:
                    request(snapshot_id, [])  # the request (or every answer) was lost
                else:
                    request(assembly.first.snapshot_id, missing[:MAX_REQUESTED_CHUNKS])
        else:
            got = len(assembly.chunks)
            total = assembly.first.num_chunks if assembly.first else "?"
            raise FetchError(f"snapshot incomplete after {timeout_s} s ({got} of {total} chunks) at "
                             f"{getattr(transport, 'url', '?')}: is octomap-rt-server running there?")
    finally:
        transport.unsubscribe(sub)
    first = assembly.first
    blob = b"".join(bytes(assembly.chunks[i].data) for i in range(first.num_chunks))
    if len(blob) != first.total_size or fnv1a64(blob) != first.blob_hash:
        raise FetchError(f"snapshot {first.snapshot_id} does not check out: {len(blob)} bytes "
                         f"(expected {first.total_size}) or wrong hash")
    data = _decompress(blob, first.compression, first.uncompressed_size)
    if len(data) != first.uncompressed_size:
        raise FetchError(f"snapshot {first.snapshot_id}: {len(data)} bytes once decompressed, "
                         f"expected {first.uncompressed_size}")
    return Snapshot(first.snapshot_id, first.num_scans, fmt, data, len(blob), first.num_chunks,
                    len(request_ids), time.monotonic() - start, first.map_epoch)
