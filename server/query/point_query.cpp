#include "query/point_query.h"

#include <cmath>
#include <string>

#include "query/key_box.h"

namespace ort::query {

unsigned checked_depth(const octomap::OcTree& tree, int depth) {
  const int top = static_cast<int>(tree.getTreeDepth());
  if (depth < 0 || depth > top)
    throw QueryError("depth " + std::to_string(depth) + " is not in 0.." + std::to_string(top) + " (0 = finest level)");
  return static_cast<unsigned>(depth);
}

PointAnswer query_point(const octomap::OcTree& tree, const octomap::point3d& p, unsigned depth) {
  PointAnswer a;
  if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) return a;
  // search(point, depth) without its error print for points outside the key range: the
  // same key conversion, the same null answer.
  octomap::OcTreeKey key;
  if (!checked_key(tree, p, key)) return a;
  const octomap::OcTreeNode* node = tree.search(key, depth);
  if (!node) return a;
  a.state = tree.isNodeOccupied(node) ? VoxelState::kOccupied : VoxelState::kFree;
  a.probability = static_cast<float>(node->getOccupancy());
  return a;
}

std::vector<PointAnswer> query_points(const octomap::OcTree& tree, std::span<const float> xyz, int depth) {
  if (xyz.size() % 3 != 0) throw QueryError("point coordinates are not a multiple of 3");
  const unsigned d = checked_depth(tree, depth);
  std::vector<PointAnswer> out;
  out.reserve(xyz.size() / 3);
  for (size_t i = 0; i + 2 < xyz.size(); i += 3)
    out.push_back(query_point(tree, octomap::point3d(xyz[i], xyz[i + 1], xyz[i + 2]), d));
  return out;
}

}  // namespace ort::query
