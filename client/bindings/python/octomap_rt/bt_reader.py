"""OctoMap's binary format (.bt, OcTree::writeBinary) read without OctoMap: the leaves as
voxel centres and sizes in numpy arrays.

Format: text header lines ("# Octomap OcTree binary file", "id OcTree", "size N",
"res R", "data"), then the tree depth first from the root: per node two bytes holding two
bits per child (children 0-3, then 4-7; child i at bits 2i, 2i+1 counted from the least
significant: 01 occupied leaf, 10 free leaf, 11 inner node, 00 unknown), followed by the
inner children's own records in child order. Child i lies at +x if i & 1, +y if i & 2,
+z if i & 4; the root spans keys [0, 2^16), key 2^15 at coordinate 0.
"""

from dataclasses import dataclass

TREE_DEPTH = 16
_CENTRE_KEY = 1 << (TREE_DEPTH - 1)


class BtFormatError(ValueError):
    """Not an OctoMap binary OcTree (the message says what was wrong)."""


@dataclass
class BtMap:
    resolution: float
    occupied: "numpy.ndarray"       # (N, 3) float64 voxel centres [m]
    occupied_size: "numpy.ndarray"  # (N,) edge lengths [m] (pruned leaves are larger)
    free: "numpy.ndarray"           # (M, 3)
    free_size: "numpy.ndarray"      # (M,)


def _header(blob: bytes):
    """(resolution, byte offset of the tree data; None for an empty tree)."""
    pos, first, fields = 0, True, {}
    while True:
        end = blob.find(b"\n", pos)
        if end < 0:
            raise BtFormatError("no 'data' line: not an OctoMap binary file")
        line = blob[pos:end].decode("ascii", "replace").strip()
        pos = end + 1
        if first:
            if not line.startswith("# Octomap OcTree binary file"):
                raise BtFormatError(f"first line is {line[:40]!r}, not '# Octomap OcTree binary file'")
            first = False
            continue
        if line.startswith("#") or not line:
            continue
        if line == "data":
            break
        key, _, value = line.partition(" ")
        fields[key] = value.strip()
    if fields.get("id", "OcTree") != "OcTree":
        raise BtFormatError(f"tree type {fields['id']!r}, not OcTree")
    try:
        resolution = float(fields["res"])
    except (KeyError, ValueError):
        raise BtFormatError("missing or bad 'res' line") from None
    # An empty tree (size 0) has no node records after the 'data' line.
    return resolution, (None if fields.get("size") == "0" else pos)


def read_bt_leaves(blob: bytes):
    """(resolution, {(depth, kx, ky, kz): occupied}) of a .bt file's bytes: every leaf by its
    depth and its smallest key (OctoMap keys), True where occupied."""
    resolution, pos = _header(blob)
    out = {}
    for key, depth, occupied in _leaves(blob, pos):
        out[(depth,) + key] = occupied
    return resolution, out


def _leaves(blob: bytes, pos: int):
    """(smallest key, depth, occupied) of every leaf from byte `pos` on, in the writer's order."""
    # Depth-first, in the writer's order: (key origin, depth) of the nodes still to read.
    if pos is None:
        return
    n = len(blob)
    stack = [((0, 0, 0), 0)]
    while stack:
        origin, depth = stack.pop()
        if pos + 2 > n:
            raise BtFormatError(f"data ends inside the tree (at byte {pos})")
        bits = blob[pos] | (blob[pos + 1] << 8)
        pos += 2
        half = 1 << (TREE_DEPTH - depth - 1)
        inner = []
        for i in range(8):
            code = (bits >> (2 * i)) & 3
            if code == 0:
                continue
            child = (origin[0] + (half if i & 1 else 0), origin[1] + (half if i & 2 else 0),
                     origin[2] + (half if i & 4 else 0))
            if code == 3:
                inner.append((child, depth + 1))
            else:  # 1: bit 2i set, bit 2i+1 clear: free leaf; 2: bit 2i+1 set: occupied leaf
                yield child, depth + 1, code == 2
        stack.extend(reversed(inner))  # first child on top: the writer's order


def read_bt(blob: bytes) -> BtMap:
    """The leaves of a .bt file's tree (the bytes of the file, e.g. a snapshot's data)."""
    import numpy as np

    resolution, pos = _header(blob)
    occ_keys, occ_depth, free_keys, free_depth = [], [], [], []
    for key, depth, occupied in _leaves(blob, pos):
        (occ_keys if occupied else free_keys).append(key)
        (occ_depth if occupied else free_depth).append(depth)

    def centres(keys, depths):
        k = np.asarray(keys, dtype=np.float64).reshape(-1, 3)
        size = np.ldexp(1.0, TREE_DEPTH - np.asarray(depths, dtype=np.int64))  # in keys
        return (k - _CENTRE_KEY + size[:, None] / 2) * resolution, size * resolution

    occ, occ_size = centres(occ_keys, occ_depth)
    free, free_size = centres(free_keys, free_depth)
    return BtMap(resolution, occ, occ_size, free, free_size)


def read_bt_file(path: str) -> BtMap:
    with open(path, "rb") as f:
        return read_bt(f.read())
