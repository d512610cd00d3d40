#include "query/ray_query.h"

#include <cmath>

#include "query/key_box.h"

namespace ort::query {
namespace {
bool finite(const octomap::point3d& p) { return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()); }
}  // namespace

RayAnswer cast_ray(const octomap::OcTree& tree, const octomap::point3d& origin, const octomap::point3d& direction,
                   const RayBatchOptions& opt) {
  if (!finite(origin)) throw QueryError("ray origin is not finite");
  if (!finite(direction)) throw QueryError("ray direction is not finite");
  // castRay normalizes in float; a direction whose float norm is 0 (or subnormal) would
  // become NaN there, one whose norm overflows (components ~1e19 and up) would become 0,
  // which castRay refuses with an error print ("direction (0,0,0)", found by fuzzing).
  const float norm = direction.norm();
  if (!(norm >= 1e-12f)) throw QueryError("ray direction is zero");
  if (!std::isfinite(norm)) throw QueryError("ray direction is too long to normalize in float; scale it down");
  RayAnswer a;
  octomap::OcTreeKey key;
  if (!checked_key(tree, origin, key)) {
    a.end = origin;
    return a;
  }
  a.hit = tree.castRay(origin, direction, a.end, opt.ignore_unknown, opt.max_range);
  if (!checked_key(tree, a.end, key)) return a;
  if (const octomap::OcTreeNode* n = tree.search(key))
    a.end_state = tree.isNodeOccupied(n) ? VoxelState::kOccupied : VoxelState::kFree;
  return a;
}

std::vector<RayAnswer> cast_rays(const octomap::OcTree& tree, std::span<const float> origins,
                                 std::span<const float> directions, const RayBatchOptions& opt) {
  if (origins.size() != directions.size() || origins.size() % 3 != 0)
    throw QueryError("ray origins and directions must be 3 numbers per ray, as many of each");
  std::vector<RayAnswer> out;
  out.reserve(origins.size() / 3);
  for (size_t i = 0; i + 2 < origins.size(); i += 3)
    out.push_back(cast_ray(tree, octomap::point3d(origins[i], origins[i + 1], origins[i + 2]),
                           octomap::point3d(directions[i], directions[i + 1], directions[i + 2]), opt));
  return out;
}

}  // namespace ort::query
