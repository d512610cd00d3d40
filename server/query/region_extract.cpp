#include "query/region_extract.h"

#include <string>

#include "query/leaf_walk.h"
#include "query/point_query.h"

namespace ort::query {

std::vector<RegionVoxel> extract_region(const octomap::OcTree& tree, const KeyBox& box, const RegionOptions& opt,
                                        WorkBudget* budget) {
  const unsigned depth = checked_depth(tree, opt.depth);
  const unsigned top = tree.getTreeDepth();
  std::vector<RegionVoxel> out;
  bool too_many = false;
  for_each_node_in(
      tree, box, depth,
      [&](const octomap::OcTreeNode& node, const NodeCube& cube, int64_t) {
        const bool occupied = tree.isNodeOccupied(node);
        if (!occupied && !opt.include_free) return true;
        if (out.size() == opt.max_voxels) {
          too_many = true;
          return false;
        }
        RegionVoxel v;
        v.lo = cube.lo;
        v.state = occupied ? VoxelState::kOccupied : VoxelState::kFree;
        // The side gives the depth back: side = 2^(top - depth).
        unsigned d = top;
        for (int s = cube.side; s > 1; s >>= 1) --d;
        v.depth = static_cast<uint8_t>(d);
        octomap::OcTreeKey center = cube.lo;
        if (cube.side > 1)
          for (int i = 0; i < 3; ++i) center[i] = octomap::key_type(cube.lo[i] + cube.side / 2);
        v.center = tree.keyToCoord(center, d);
        out.push_back(v);
        return true;
      },
      budget);
  if (too_many)
    throw QueryError("region has more than " + std::to_string(opt.max_voxels) +
                     " voxels: ask for a smaller box or a coarser depth");
  return out;
}

}  // namespace ort::query
