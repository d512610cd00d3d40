// Point queries: OctoMap's own answer for a point at a depth, i.e. search(point, depth),
// then isNodeOccupied and getOccupancy on the node found; no node means unknown.
#pragma once

#include <span>
#include <vector>

#include <octomap/OcTree.h>

#include "query/query_types.h"

namespace ort::query {

// `depth`: 1 .. tree depth, or 0 for the finest level (OctoMap's convention). Throws
// QueryError for a depth the tree does not have. A non-finite point is unknown (OctoMap
// would convert it to a key with undefined behaviour; the server refuses such queries).
unsigned checked_depth(const octomap::OcTree& tree, int depth);
PointAnswer query_point(const octomap::OcTree& tree, const octomap::point3d& p, unsigned depth = 0);
// xyz: x0 y0 z0 x1 ... ; one answer per point, in order.
std::vector<PointAnswer> query_points(const octomap::OcTree& tree, std::span<const float> xyz, int depth = 0);

}  // namespace ort::query
