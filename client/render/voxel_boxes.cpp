#include "render/voxel_boxes.h"

#include <algorithm>
#include <limits>

namespace ort::render {

Box3 Box3::none() {
  const double inf = std::numeric_limits<double>::infinity();
  return Box3{{inf, inf, inf}, {-inf, -inf, -inf}};
}

void Box3::extend(const Box3& b) {
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::min(lo[k], b.lo[k]);
    hi[k] = std::max(hi[k], b.hi[k]);
  }
}

namespace {

// The leaf's box cut to the height range, or nothing when it lies outside.
std::optional<VoxelBox> clipped_leaf(const octomap::OcTree::leaf_iterator& it, const HeightRange& range) {
  const double half = it.getSize() / 2;
  const octomap::point3d c = it.getCoordinate();
  VoxelBox b{{float(c.x() - half), float(c.y() - half), float(c.z() - half)},
             {float(c.x() + half), float(c.y() + half), float(c.z() + half)}};
  if (range.min) b.lo[2] = std::max(b.lo[2], float(*range.min));
  if (range.max) b.hi[2] = std::min(b.hi[2], float(*range.max));
  if (b.lo[2] >= b.hi[2]) return std::nullopt;
  return b;
}

Box3 as_box3(const VoxelBox& b) { return Box3{{b.lo[0], b.lo[1], b.lo[2]}, {b.hi[0], b.hi[1], b.hi[2]}}; }

}  // namespace

MapBoxes collect_boxes(const octomap::OcTree& tree, const HeightRange& range, bool with_free) {
  MapBoxes out;
  out.resolution = tree.getResolution();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const bool occupied = tree.isNodeOccupied(*it);
    if (!occupied && !with_free) continue;
    const auto box = clipped_leaf(it, range);
    if (!box) continue;
    if (occupied) {
      out.occupied.push_back(*box);
      out.occupied_bounds.extend(as_box3(*box));
    } else {
      out.free.push_back(*box);
      out.free_bounds.extend(as_box3(*box));
    }
  }
  return out;
}

}  // namespace ort::render
