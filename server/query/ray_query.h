// Ray queries: exactly OcTree::castRay on the map (OctoMap's DDA through the key grid:
// stops at the first occupied voxel, at unknown space unless ignore_unknown, past
// max_range, or at the key range's edge), plus the state of the voxel where it stopped.
#pragma once

#include <functional>
#include <span>
#include <vector>

#include <octomap/OcTree.h>

#include "query/query_types.h"
#include "query/work_budget.h"

namespace ort::query {

struct RayBatchOptions {
  bool ignore_unknown = false;
  double max_range = -1;  // <= 0: no limit (castRay's default)
  // A shard's voxels (docs/PROTOCOL.md, "Shards"): when set, the ray takes castRay's walk but
  // passes every voxel it does not own as free (another shard answers for it), so it stops at
  // the first occupied voxel, or unknown one unless ignore_unknown, among its own only; past
  // max_range and at the key range's edge as castRay. Empty: castRay itself.
  std::function<bool(const octomap::OcTreeKey&)> owns;
};

// One ray. With opt.owns, castRay's walk restricted to the owned voxels (see above). An origin outside the map's key range gives hit = false, end = origin, unknown
// (castRay would return false there too, after printing a warning). Throws QueryError for a
// non-finite origin or direction, or a zero direction.
RayAnswer cast_ray(const octomap::OcTree& tree, const octomap::point3d& origin, const octomap::point3d& direction,
                   const RayBatchOptions& opt);
// The most key steps castRay may take on this ray (its range, or the key range's edge where
// there is none), what a budget must hold before the ray is cast: castRay cannot be stopped
// once it runs.
uint64_t ray_walk_bound(const octomap::OcTree& tree, const octomap::point3d& direction, const RayBatchOptions& opt);

// origins, directions: x0 y0 z0 x1 ...; one answer per ray, in order.
// With a budget: a ray is cast only while the budget is not spent and its walk bound fits
// max_work; it then costs the key steps it took. Fewer answers than rays: budget->cut says
// why, and the answers are those of the first rays.
std::vector<RayAnswer> cast_rays(const octomap::OcTree& tree, std::span<const float> origins,
                                 std::span<const float> directions, const RayBatchOptions& opt,
                                 WorkBudget* budget = nullptr);

}  // namespace ort::query
