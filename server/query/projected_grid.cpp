#include "query/projected_grid.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "query/key_box.h"
#include "query/leaf_walk.h"

namespace ort::query {
namespace {

int64_t floor_div(int64_t a, int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// Key range [lo, hi] of stored leaves in x and y; false for an empty tree.
bool map_key_extent(const octomap::OcTree& tree, int lo[2], int hi[2], WorkBudget* budget) {
  if (!tree.getRoot()) return false;
  const unsigned top = tree.getTreeDepth();
  lo[0] = lo[1] = 1 << top;
  hi[0] = hi[1] = -1;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (budget && !budget->charge(1)) return false;
    const NodeCube c = node_cube(it.getKey(), it.getDepth(), top);
    for (int i = 0; i < 2; ++i) {
      lo[i] = std::min<int>(lo[i], c.lo[i]);
      hi[i] = std::max<int>(hi[i], c.lo[i] + c.side - 1);
    }
  }
  return hi[0] >= 0;
}

void check_finite(double v, const char* what) {
  if (!std::isfinite(v)) throw QueryError(std::string(what) + " is not finite");
}

}  // namespace

Grid2D projected_grid(const octomap::OcTree& tree, const GridRequest& req, WorkBudget* budget) {
  check_finite(req.z_min, "z min");
  check_finite(req.z_max, "z max");
  if (req.z_min > req.z_max) throw QueryError("z band min > max");
  if (req.cell_voxels < 1 || req.cell_voxels > (1 << 15))
    throw QueryError("cell size must be 1..32768 times the resolution");
  const int m = req.cell_voxels;
  const int origin_key = 1 << (tree.getTreeDepth() - 1);  // key of coordinate 0
  Grid2D g;
  g.cell_voxels = m;
  g.cell_size = m * tree.getResolution();
  g.key_z0 = clamped_key(tree, req.z_min);
  g.key_z1 = clamped_key(tree, req.z_max);
  int lo[2], hi[2];
  if (req.window) {
    for (double v : {req.x_min, req.y_min, req.x_max, req.y_max}) check_finite(v, "grid window corner");
    if (req.x_min > req.x_max || req.y_min > req.y_max) throw QueryError("grid window min > max");
    lo[0] = clamped_key(tree, req.x_min), lo[1] = clamped_key(tree, req.y_min);
    hi[0] = clamped_key(tree, req.x_max), hi[1] = clamped_key(tree, req.y_max);
  } else if (!map_key_extent(tree, lo, hi, budget)) {
    return g;  // empty map (or the budget ran out): a 0 x 0 grid
  }
  int first[2], count[2];
  for (int i = 0; i < 2; ++i) {
    first[i] = origin_key + static_cast<int>(floor_div(lo[i] - origin_key, m) * m);
    count[i] = static_cast<int>(floor_div(hi[i] - first[i], m) + 1);
  }
  if (int64_t(count[0]) * count[1] > req.max_cells)
    throw QueryError("grid of " + std::to_string(count[0]) + " x " + std::to_string(count[1]) + " cells exceeds " +
                     std::to_string(req.max_cells) + ": use a larger cell or a smaller window");
  g.key_x0 = first[0], g.key_y0 = first[1];
  g.width = count[0], g.height = count[1];
  g.origin_x = (first[0] - origin_key) * tree.getResolution();
  g.origin_y = (first[1] - origin_key) * tree.getResolution();
  g.cells.assign(size_t(g.width) * g.height, VoxelState::kUnknown);

  const int top_key = (1 << tree.getTreeDepth()) - 1;
  KeyBox box;
  box.min = octomap::OcTreeKey(std::max(first[0], 0), std::max(first[1], 0), g.key_z0);
  box.max = octomap::OcTreeKey(std::min(first[0] + count[0] * m - 1, top_key),
                               std::min(first[1] + count[1] * m - 1, top_key), g.key_z1);
  for_each_node_in(
      tree, box, 0,
      [&](const octomap::OcTreeNode& node, const NodeCube& c, int64_t) {
        const VoxelState s = tree.isNodeOccupied(node) ? VoxelState::kOccupied : VoxelState::kFree;
        int cell_lo[2], cell_hi[2];
        for (int i = 0; i < 2; ++i) {
          const int a = std::max<int>(c.lo[i], box.min[i]), b = std::min<int>(c.lo[i] + c.side - 1, box.max[i]);
          cell_lo[i] = (a - first[i]) / m;
          cell_hi[i] = (b - first[i]) / m;
        }
        for (int j = cell_lo[1]; j <= cell_hi[1]; ++j)
          for (int i = cell_lo[0]; i <= cell_hi[0]; ++i) {
            VoxelState& cell = g.cells[size_t(j) * g.width + i];
            if (s == VoxelState::kOccupied || cell == VoxelState::kUnknown) cell = s;
          }
        return true;
      },
      budget);
  return g;
}

}  // namespace ort::query
