#include "query/ray_query.h"

#include <cmath>
#include <limits>

#include "query/key_box.h"

namespace ort::query {
namespace {
bool finite(const octomap::point3d& p) { return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()); }

// The keys a walk from a to b stepped through: one per boundary crossed, plus the start.
uint64_t key_steps(const octomap::OcTree& tree, const octomap::point3d& a, const octomap::point3d& b) {
  uint64_t n = 1;
  for (int i = 0; i < 3; ++i)
    n += clamped_key(tree, b(i)) > clamped_key(tree, a(i)) ? clamped_key(tree, b(i)) - clamped_key(tree, a(i))
                                                           : clamped_key(tree, a(i)) - clamped_key(tree, b(i));
  return n;
}

// castRay's walk (OccupancyOcTreeBase::castRay of OctoMap 1.9: the same float and double
// arithmetic, step for step, so a shard's walk visits the keys the one map's castRay visits)
// stopping only at voxels `owns` accepts. The origin's key is checked by the caller.
bool walk_owned(const octomap::OcTree& tree, const octomap::point3d& origin, const octomap::point3d& direction_in,
                const RayBatchOptions& opt, octomap::OcTreeKey key, octomap::point3d& end) {
  // true: the walk stops at `k` (end is set); `hit` says whether it stopped at an occupied voxel.
  bool hit = false;
  const auto stops_at = [&](const octomap::OcTreeKey& k) {
    if (!opt.owns(k)) return false;
    const octomap::OcTreeNode* n = tree.search(k);
    if (n) hit = tree.isNodeOccupied(n);
    return hit || (!n && !opt.ignore_unknown);
  };
  if (stops_at(key)) {
    end = tree.keyToCoord(key);
    return hit;
  }
  const octomap::point3d direction = direction_in.normalized();
  const double res = tree.getResolution();
  const unsigned top = (1u << tree.getTreeDepth()) - 1;  // castRay's 2 * tree_max_val - 1
  int step[3];
  double t_max[3], t_delta[3];
  for (int i = 0; i < 3; ++i) {
    step[i] = direction(i) > 0.0 ? 1 : direction(i) < 0.0 ? -1 : 0;
    if (step[i] != 0) {
      double border = tree.keyToCoord(key[i]);
      border += double(step[i] * res * 0.5);
      t_max[i] = (border - origin(i)) / direction(i);
      t_delta[i] = res / std::fabs(direction(i));
    } else {
      t_max[i] = t_delta[i] = std::numeric_limits<double>::max();
    }
  }
  if (step[0] == 0 && step[1] == 0 && step[2] == 0) return false;
  const bool max_range_set = opt.max_range > 0.0;
  const double max_range_sq = opt.max_range * opt.max_range;
  for (;;) {
    const int dim = t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
    if ((step[dim] < 0 && key[dim] == 0) || (step[dim] > 0 && key[dim] == top)) {
      end = tree.keyToCoord(key);
      return false;
    }
    key[dim] = static_cast<octomap::key_type>(key[dim] + step[dim]);
    t_max[dim] += t_delta[dim];
    end = tree.keyToCoord(key);
    if (max_range_set) {
      double dist_sq = 0.0;
      for (int j = 0; j < 3; ++j) dist_sq += ((end(j) - origin(j)) * (end(j) - origin(j)));
      if (dist_sq > max_range_sq) return false;
    }
    if (stops_at(key)) return hit;
  }
}
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
  a.hit = opt.owns ? walk_owned(tree, origin, direction, opt, key, a.end)
                   : tree.castRay(origin, direction, a.end, opt.ignore_unknown, opt.max_range);
  if (!checked_key(tree, a.end, key)) return a;
  if (const octomap::OcTreeNode* n = tree.search(key))
    a.end_state = tree.isNodeOccupied(n) ? VoxelState::kOccupied : VoxelState::kFree;
  return a;
}

uint64_t ray_walk_bound(const octomap::OcTree& tree, const octomap::point3d& direction, const RayBatchOptions& opt) {
  const uint64_t edge = 3ull << tree.getTreeDepth();  // every key of the range, on each axis
  const double norm = direction.norm();
  // An infinite or NaN direction or range (a query field, unchecked here) has no walk bound of
  // its own: the whole key range is the bound, never a float-to-integer cast of NaN.
  if (!(opt.max_range > 0) || !(norm > 0) || !std::isfinite(norm) || !std::isfinite(opt.max_range)) return edge;
  // The DDA steps once per voxel boundary crossed: |d|_1 / |d|_2 * range / resolution per
  // ray, plus the start voxel and one boundary per axis at each end.
  const double l1 = std::abs(direction.x()) + std::abs(direction.y()) + std::abs(direction.z());
  const double steps = l1 / norm * opt.max_range / tree.getResolution() + 4;
  return !(steps < static_cast<double>(edge)) ? edge : static_cast<uint64_t>(steps);
}

std::vector<RayAnswer> cast_rays(const octomap::OcTree& tree, std::span<const float> origins,
                                 std::span<const float> directions, const RayBatchOptions& opt, WorkBudget* budget) {
  if (origins.size() != directions.size() || origins.size() % 3 != 0)
    throw QueryError("ray origins and directions must be 3 numbers per ray, as many of each");
  std::vector<RayAnswer> out;
  out.reserve(origins.size() / 3);
  for (size_t i = 0; i + 2 < origins.size(); i += 3) {
    const octomap::point3d origin(origins[i], origins[i + 1], origins[i + 2]);
    const octomap::point3d direction(directions[i], directions[i + 1], directions[i + 2]);
    if (budget) {
      // Not before the first ray: a ray is bounded by the work bound below, and a turn that
      // lost the core for the time bound before it started (a loaded machine) would answer
      // nothing, so a client resending the rest would never progress.
      if (!out.empty() && !budget->check_now()) break;
      const uint64_t bound = ray_walk_bound(tree, direction, opt);
      if (bound > budget->max_work || budget->used > budget->max_work) {
        budget->stop_with(Cut::kWork);
        break;
      }
    }
    out.push_back(cast_ray(tree, origin, direction, opt));
    if (budget) budget->charge(key_steps(tree, origin, out.back().end));
  }
  return out;
}

}  // namespace ort::query
