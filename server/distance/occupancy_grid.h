// The obstacles of a box of the map as a dense grid of cells: what the distance transform
// runs on. Read from the OcTree under the caller's (shared) map lock; nothing after it needs
// the tree.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <octomap/OcTree.h>

#include "distance/distance_types.h"

namespace ort::distance {

// A box of cells in key space: cell (i, j, k) holds the finest keys
// key_lo[a] + [i, i + 1) * cell_voxels on each axis. key_lo may lie outside the key range
// [0, 2^16) (a box padded past the map's edge): those voxels are unknown.
struct CellBox {
  std::array<int64_t, 3> key_lo{0, 0, 0};
  GridDims dims;
  int cell_voxels = 1;
};

// Whether two boxes are the same cells.
inline bool same_cells(const CellBox& a, const CellBox& b) {
  return a.key_lo == b.key_lo && a.cell_voxels == b.cell_voxels && a.dims.nx == b.dims.nx && a.dims.ny == b.dims.ny &&
         a.dims.nz == b.dims.nz;
}

struct OccupancyGrid {
  CellBox box;
  std::vector<uint8_t> occupied;  // dims.cells(), 1 = obstacle
};

// The cells (aligned to multiples of cell_voxels) that hold the finest keys [lo, hi] (per
// axis, inclusive), grown by `pad` cells on every side.
CellBox cell_box_around(const std::array<int64_t, 3>& key_lo, const std::array<int64_t, 3>& key_hi, int cell_voxels,
                        int pad);

// Obstacle cells of `box`: a cell is an obstacle if any finest voxel in it is occupied, or
// (unknown == kOccupied) not known free. One walk of the stored leaves that touch the box.
// With `own.owns`, the voxels of regions it does not own count as known free (a shard's share
// of the obstacles: distance_types.h).
OccupancyGrid read_occupancy(const octomap::OcTree& tree, const CellBox& box, UnknownAs unknown,
                             const RegionOwnership& own = {});

}  // namespace ort::distance
