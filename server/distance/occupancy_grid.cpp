#include "distance/occupancy_grid.h"

#include <algorithm>
#include <string>

namespace ort::distance {
namespace {

int64_t floor_div(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// The cells of one axis a node's key interval [c0, c1] touches, with the voxels it shares with each.
struct AxisSpan {
  int64_t first = 0, last = -1;  // cell indices, inclusive
  std::vector<int32_t> shared;   // per cell of [first, last]
};

AxisSpan axis_span(int64_t c0, int64_t c1, int64_t key_lo, int n, int m) {
  AxisSpan s;
  const int64_t b0 = key_lo, b1 = key_lo + int64_t(n) * m - 1;
  const int64_t lo = std::max(c0, b0), hi = std::min(c1, b1);
  if (hi < lo) return s;
  s.first = (lo - key_lo) / m;
  s.last = (hi - key_lo) / m;
  for (int64_t i = s.first; i <= s.last; ++i) {
    const int64_t cell0 = key_lo + i * m, cell1 = cell0 + m - 1;
    s.shared.push_back(static_cast<int32_t>(std::min(c1, cell1) - std::max(c0, cell0) + 1));
  }
  return s;
}

}  // namespace

CellBox cell_box_around(const std::array<int64_t, 3>& key_lo, const std::array<int64_t, 3>& key_hi, int cell_voxels,
                        int pad) {
  if (cell_voxels < 1 || cell_voxels > kMaxCellVoxels)
    throw DistanceError("cell_voxels must be in 1.." + std::to_string(kMaxCellVoxels));
  CellBox b;
  b.cell_voxels = cell_voxels;
  int64_t n[3];
  for (int a = 0; a < 3; ++a) {
    const int64_t c0 = floor_div(key_lo[a], cell_voxels), c1 = floor_div(key_hi[a], cell_voxels);
    n[a] = c1 - c0 + 1 + 2 * int64_t(pad);
    if (n[a] < 1 || n[a] > kMaxGridAxis)
      throw DistanceError("the padded box has " + std::to_string(n[a]) + " cells on an axis (at most " +
                          std::to_string(kMaxGridAxis) + ")");
    b.key_lo[a] = (c0 - pad) * cell_voxels;
  }
  b.dims = GridDims{int(n[0]), int(n[1]), int(n[2])};
  return b;
}

OccupancyGrid read_occupancy(const octomap::OcTree& tree, const CellBox& box, UnknownAs unknown,
                             const RegionOwnership& own) {
  OccupancyGrid g;
  g.box = box;
  const int m = box.cell_voxels;
  const int nx = box.dims.nx, ny = box.dims.ny, nz = box.dims.nz;
  g.occupied.assign(static_cast<size_t>(box.dims.cells()), 0);
  const bool unknown_blocks = unknown == UnknownAs::kOccupied;
  const int64_t full = int64_t(m) * m * m;
  // Per cell: finest voxels known free (only needed where unknown counts as an obstacle).
  std::vector<int32_t> free_voxels(unknown_blocks ? g.occupied.size() : 0, 0);

  const unsigned depth = tree.getTreeDepth();
  const int64_t key_top = (int64_t(1) << depth) - 1;
  octomap::OcTreeKey kmin, kmax;
  bool inside = true;
  const int n[3] = {nx, ny, nz};
  for (int a = 0; a < 3; ++a) {
    const int64_t lo = std::max<int64_t>(box.key_lo[a], 0);
    const int64_t hi = std::min<int64_t>(box.key_lo[a] + int64_t(n[a]) * m - 1, key_top);
    if (hi < lo) inside = false;
    kmin[a] = static_cast<octomap::key_type>(std::clamp<int64_t>(lo, 0, key_top));
    kmax[a] = static_cast<octomap::key_type>(std::clamp<int64_t>(hi, 0, key_top));
  }
  // Adds the voxels a known-free cube [c0, c0 + side) shares with each cell it touches.
  auto add_free = [&](const AxisSpan(&s)[3]) {
    for (int64_t k = s[2].first; k <= s[2].last; ++k)
      for (int64_t j = s[1].first; j <= s[1].last; ++j) {
        const size_t row = static_cast<size_t>((k * ny + j) * nx);
        const int32_t yz = s[1].shared[j - s[1].first] * s[2].shared[k - s[2].first];
        for (int64_t i = s[0].first; i <= s[0].last; ++i) free_voxels[row + i] += yz * s[0].shared[i - s[0].first];
      }
  };
  if (inside && unknown_blocks && own.owns) {  // other shards' regions: theirs to count
    const unsigned shift = depth - std::min(own.region_depth, depth);
    const int64_t side = int64_t(1) << shift;
    for (uint32_t rz = kmin[2] >> shift; rz <= uint32_t(kmax[2] >> shift); ++rz)
      for (uint32_t ry = kmin[1] >> shift; ry <= uint32_t(kmax[1] >> shift); ++ry)
        for (uint32_t rx = kmin[0] >> shift; rx <= uint32_t(kmax[0] >> shift); ++rx) {
          if (own.owns(rx, ry, rz)) continue;
          const uint32_t r[3] = {rx, ry, rz};
          AxisSpan s[3];
          for (int a = 0; a < 3; ++a)
            s[a] = axis_span(int64_t(r[a]) << shift, (int64_t(r[a]) << shift) + side - 1, box.key_lo[a], n[a], m);
          add_free(s);
        }
  }
  if (inside && tree.getRoot()) {
    for (auto it = tree.begin_leafs_bbx(kmin, kmax), end = tree.end_leafs_bbx(); it != end; ++it) {
      const bool occ = tree.isNodeOccupied(*it);
      if (!occ && !unknown_blocks) continue;
      const int64_t side = int64_t(1) << (depth - it.getDepth());
      const octomap::OcTreeKey key = it.getKey();
      AxisSpan s[3];
      bool touches = true;
      for (int a = 0; a < 3; ++a) {
        const int64_t c0 = int64_t(key[a]) & ~(side - 1);
        s[a] = axis_span(c0, c0 + side - 1, box.key_lo[a], n[a], m);
        if (s[a].last < s[a].first) touches = false;
      }
      // The bbx iterator also yields nodes that end one voxel below the box (query/leaf_walk.h).
      if (!touches) continue;
      if (!occ) {
        add_free(s);
        continue;
      }
      for (int64_t k = s[2].first; k <= s[2].last; ++k)
        for (int64_t j = s[1].first; j <= s[1].last; ++j) {
          const size_t row = static_cast<size_t>((k * ny + j) * nx);
          std::fill(g.occupied.begin() + row + s[0].first, g.occupied.begin() + row + s[0].last + 1, uint8_t(1));
        }
    }
  }
  if (unknown_blocks)
    for (size_t c = 0; c < g.occupied.size(); ++c)
      if (free_voxels[c] < full) g.occupied[c] = 1;
  return g;
}

}  // namespace ort::distance
