"""Distance to the nearest obstacle from octomap-rt-server (docs/PROTOCOL.md, "Distance
queries"): points, a dense box and a path's clearance, numpy in and out. Same conventions as
octomap_rt.queries (a QueryChannel, one datagram a request, re-sent when unanswered)."""

from ._types import distance_box_chunk_t, distance_path_reply_t, distance_points_reply_t, distance_query_t
from .protocol_table import CHUNK_DATA_BYTES as CHUNK_BYTES
from .queries import MAX_POINTS, QueryChannel, QueryError
from .snapshot_fetch import fnv1a64

NO_OBSTACLE = 0xFFFFFFFF  # squared distance beyond max_distance


def _query(mode: int, max_distance: float, unknown_occupied: bool, gradient: bool, cell_voxels: int = 1):
    m = distance_query_t()
    m.mode = mode
    m.max_distance = float(max_distance)
    m.unknown_as = distance_query_t.UNKNOWN_OCCUPIED if unknown_occupied else distance_query_t.UNKNOWN_FREE
    m.with_gradient = 1 if gradient else 0
    m.cell_voxels = int(cell_voxels)
    m.box_min, m.box_max = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
    return m


def distance_points(q: QueryChannel, points, max_distance: float = 2.0, unknown_occupied: bool = False,
                    gradient: bool = False, min_snapshot_id: int = 0):
    """(distance float32 (N,), gradient float32 (N, 3) or None) for an (N, 3) array of points:
    the distance of each point's voxel centre to the nearest occupied voxel centre, clamped."""
    import numpy as np

    pts = np.asarray(points, dtype=np.float32).reshape(-1, 3)
    dist, grad = [], []
    for start in range(0, len(pts), MAX_POINTS):
        m = _query(distance_query_t.MODE_POINTS, max_distance, unknown_occupied, gradient)
        m.xyz = pts[start:start + MAX_POINTS].reshape(-1).tolist()
        m.num_xyz = len(m.xyz)
        r = q.ask(q.channels.query_distance, m, distance_points_reply_t, min_snapshot_id)[0]
        dist.extend(r.distance)
        grad.extend(r.gradient)
    d = np.asarray(dist, dtype=np.float32)
    return d, (np.asarray(grad, dtype=np.float32).reshape(-1, 3) if gradient else None)


def _zstd_frames(zstandard, blob: bytes, size: int) -> bytes:
    """A box's blob: zstd frames (one per z-slab) concatenated, decompressed one after the other,
    never more than size + 1 bytes of output (a frame that declares less and holds more is refused)."""
    import io

    out = bytearray()
    with zstandard.ZstdDecompressor().stream_reader(io.BytesIO(blob), read_across_frames=True) as r:
        while len(out) <= size:
            part = r.read(size + 1 - len(out))
            if not part:
                break
            out += part
    if len(out) != size:
        got = f"more than {size}" if len(out) > size else str(len(out))
        raise QueryError(f"distance box: the frames decompress to {got} bytes, {size} declared")
    return bytes(out)


def distance_box(q: QueryChannel, box_min, box_max, max_distance: float = 2.0, unknown_occupied: bool = False,
                 gradient: bool = False, cell_voxels: int = 1, min_snapshot_id: int = 0):
    """The dense field of a box: a dict with 'distance' float32 [z, y, x] (metres, clamped),
    'squared' uint32 [z, y, x] (cell units, NO_OBSTACLE beyond the clamp), 'gradient'
    float32 [z, y, x, 3] or None, 'origin' (min corner of cell 0), 'cell_size', 'snapshot_id'."""
    import numpy as np
    import zstandard

    m = _query(distance_query_t.MODE_BOX, max_distance, unknown_occupied, gradient, cell_voxels)
    m.box_min, m.box_max = [float(v) for v in box_min], [float(v) for v in box_max]
    m.xyz, m.num_xyz = [], 0
    parts = q.ask(q.channels.query_distance, m, distance_box_chunk_t, min_snapshot_id,
                  complete=lambda rs: len({r.chunk_index for r in rs}) >= rs[0].num_chunks)
    first = parts[0]
    blob = bytearray(first.total_size)
    for p in {r.chunk_index: r for r in parts}.values():
        blob[p.chunk_index * CHUNK_BYTES:p.chunk_index * CHUNK_BYTES + p.num_bytes] = bytes(p.data)
    if fnv1a64(bytes(blob)) != first.blob_hash:
        raise QueryError("distance box: blob hash differs")
    raw = bytes(blob)
    if first.compression == distance_box_chunk_t.COMPRESSION_ZSTD:
        raw = _zstd_frames(zstandard, raw, first.uncompressed_size)
    nx, ny, nz = first.size
    cells = nx * ny * nz
    sq = np.frombuffer(raw, dtype="<u4", count=cells).reshape(nz, ny, nx)
    dist = np.where(sq == NO_OBSTACLE, first.max_distance,
                    np.minimum(np.sqrt(sq.astype(np.float64)) * first.cell_size, first.max_distance)).astype(np.float32)
    grad = None
    if first.with_gradient:
        grad = np.frombuffer(raw, dtype="<f4", count=3 * cells, offset=4 * cells).reshape(nz, ny, nx, 3)
    return {"distance": dist, "squared": sq, "gradient": grad, "origin": tuple(first.origin),
            "cell_size": first.cell_size, "snapshot_id": first.snapshot_id, "map_epoch": first.map_epoch}


def distance_path(q: QueryChannel, vertices, max_distance: float = 2.0, unknown_occupied: bool = False,
                  min_snapshot_id: int = 0):
    """The clearance of a polyline ((N, 3) vertices) sampled every resolution: a dict with
    'min_distance', 'min_xyz', 'min_arc_length', 'min_sample', 'num_samples'."""
    import numpy as np

    m = _query(distance_query_t.MODE_PATH, max_distance, unknown_occupied, False)
    m.xyz = np.asarray(vertices, dtype=np.float32).reshape(-1).tolist()
    m.num_xyz = len(m.xyz)
    r = q.ask(q.channels.query_distance, m, distance_path_reply_t, min_snapshot_id)[0]
    return {"min_distance": r.min_distance, "min_xyz": tuple(r.min_xyz), "min_arc_length": r.min_arc_length,
            "min_sample": r.min_sample, "num_samples": r.num_samples}
