#include "brute_force.h"

#include <algorithm>

#include "query_test_maps.h"

namespace ort::test {

using query::BoxCounts;
using query::KeyBox;
using query::VoxelState;

VoxelState voxel_state(const octomap::OcTree& t, const octomap::OcTreeKey& key) {
  const octomap::OcTreeNode* n = t.search(key);
  if (!n) return VoxelState::kUnknown;
  return t.isNodeOccupied(n) ? VoxelState::kOccupied : VoxelState::kFree;
}

BoxCounts brute_counts(const octomap::OcTree& t, const KeyBox& box) {
  BoxCounts c;
  octomap::OcTreeKey k;
  for (int x = box.min[0]; x <= box.max[0]; ++x)
    for (int y = box.min[1]; y <= box.max[1]; ++y)
      for (int z = box.min[2]; z <= box.max[2]; ++z) {
        k[0] = x, k[1] = y, k[2] = z;
        switch (voxel_state(t, k)) {
          case VoxelState::kUnknown: ++c.unknown; break;
          case VoxelState::kFree: ++c.free; break;
          case VoxelState::kOccupied: ++c.occupied; break;
        }
      }
  return c;
}

BoxCounts all_leaves_counts(const octomap::OcTree& t, const KeyBox& box) {
  BoxCounts c;
  const int top = static_cast<int>(t.getTreeDepth());
  for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it) {
    const int side = 1 << (top - static_cast<int>(it.getDepth()));
    int64_t n = 1;
    for (int i = 0; i < 3; ++i) {
      // A node's center key is its lowest key + side / 2 (side > 1), or the key (side 1).
      const int lo = it.getKey()[i] - side / 2, hi = lo + side - 1;
      n *= std::max(0, std::min(hi, int(box.max[i])) - std::max(lo, int(box.min[i])) + 1);
    }
    (t.isNodeOccupied(*it) ? c.occupied : c.free) += n;
  }
  c.unknown = box.voxels() - c.occupied - c.free;
  return c;
}

std::set<RegionEntry> brute_region(const octomap::OcTree& t, const KeyBox& box, unsigned depth, bool include_free) {
  std::set<RegionEntry> out;
  const int top = static_cast<int>(t.getTreeDepth());
  const int cell = 1 << (top - static_cast<int>(depth));
  auto first = [&](int i) { return (box.min[i] / cell) * cell; };
  for (int x = first(0); x <= box.max[0]; x += cell)
    for (int y = first(1); y <= box.max[1]; y += cell)
      for (int z = first(2); z <= box.max[2]; z += cell) {
        const octomap::OcTreeKey k(std::max<int>(x, box.min[0]), std::max<int>(y, box.min[1]),
                                   std::max<int>(z, box.min[2]));
        const octomap::OcTreeNode* n = t.search(k, depth);
        if (!n) continue;
        const bool occ = t.isNodeOccupied(n);
        if (!occ && !include_free) continue;
        // The node's depth: descend until reaching it.
        unsigned d = 0;
        for (const octomap::OcTreeNode* p = t.getRoot(); p != n; ++d)
          p = t.getNodeChild(p, octomap::computeChildIdx(k, top - 1 - d));
        const int side = 1 << (top - static_cast<int>(d));
        out.emplace(k[0] / side * side, k[1] / side * side, k[2] / side * side, int(d),
                    int(occ ? VoxelState::kOccupied : VoxelState::kFree));
      }
  return out;
}

KeyBox random_box(const octomap::OcTree& t, std::mt19937& rng, int max_side) {
  double lo[3], hi[3];
  map_extent(t, 1.0, lo, hi);
  KeyBox b;
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 3; ++i) {
    // Sides from 1 voxel up, log-uniform; corners anywhere in (and a little around) the map.
    const int side = std::max(1, static_cast<int>(std::exp(u(rng) * std::log(double(max_side)))));
    const int a = query::clamped_key(t, lo[i] + u(rng) * (hi[i] - lo[i]));
    b.min[i] = static_cast<octomap::key_type>(std::clamp(a - side / 2, 0, 65535 - side + 1));
    b.max[i] = static_cast<octomap::key_type>(b.min[i] + side - 1);
  }
  return b;
}

}  // namespace ort::test
