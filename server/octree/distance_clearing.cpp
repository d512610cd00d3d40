#include "octree/distance_clearing.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ort {

namespace {

enum class Reach { kBeyond, kWithin, kStraddles };

Reach reach(const octomap::OcTree& tree, const std::vector<octomap::point3d>& centres, double radius_sq,
            const octomap::OcTreeKey& min_key, unsigned depth) {
  const double res = tree.getResolution();
  const double size = res * double(1u << (16 - depth));
  double lo[3], hi[3];
  for (unsigned a = 0; a < 3; ++a) {
    lo[a] = tree.keyToCoord(min_key[a]) - res / 2;
    hi[a] = lo[a] + size;
  }
  bool beyond = true;
  for (const octomap::point3d& c : centres) {
    double near_sq = 0, far_sq = 0;
    for (unsigned a = 0; a < 3; ++a) {
      const double p = c(a);
      const double d_near = std::max({lo[a] - p, 0.0, p - hi[a]});
      const double d_far = std::max(std::fabs(p - lo[a]), std::fabs(hi[a] - p));
      near_sq += d_near * d_near;
      far_sq += d_far * d_far;
    }
    if (far_sq <= radius_sq) return Reach::kWithin;
    if (near_sq <= radius_sq) beyond = false;
  }
  return beyond ? Reach::kBeyond : Reach::kStraddles;
}

// Clears the subtree of `node`: true when `node` must go.
bool clear_node(octomap::OcTree& tree, const std::vector<octomap::point3d>& centres, double radius_sq,
                octomap::OcTreeNode* node, unsigned depth, const octomap::OcTreeKey& min_key, uint64_t& visited,
                uint64_t& deleted) {
  ++visited;
  const Reach r = reach(tree, centres, radius_sq, min_key, depth);
  if (r == Reach::kBeyond) return true;
  if (r == Reach::kWithin || !tree.nodeHasChildren(node)) return false;
  for (unsigned i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i)) continue;
    if (clear_node(tree, centres, radius_sq, tree.getNodeChild(node, i), depth + 1, child_min_key(min_key, depth, i),
                   visited, deleted)) {
      delete_subtree(tree, node, i);
      ++deleted;
    }
  }
  if (!tree.nodeHasChildren(node)) {
    free_empty_child_array(node);
    return true;
  }
  node->updateOccupancyChildren();
  return false;
}

}  // namespace

DistanceClearingSweep::DistanceClearingSweep(const octomap::OcTree& tree, const RegionGrid& grid,
                                             std::vector<octomap::point3d> centres, double radius)
    : sweep_(tree, grid),
      centres_(std::make_shared<const std::vector<octomap::point3d>>(std::move(centres))),
      radius_sq_(radius * radius) {
  if (!std::isfinite(radius) || radius <= 0)
    throw std::invalid_argument("clearing radius " + std::to_string(radius) + " m is not a positive number");
  stand_ins_.now = [centres = centres_, r2 = radius_sq_](octomap::OcTree& t, octomap::OcTreeNode*, unsigned depth,
                                                         const octomap::OcTreeKey& min_key) {
    switch (reach(t, *centres, r2, min_key, depth)) {
      case Reach::kBeyond: return StandInFate::kGone;
      case Reach::kWithin: return StandInFate::kUnchanged;
      case Reach::kStraddles: break;
    }
    return StandInFate::kOwes;
  };
  stand_ins_.owed = std::make_shared<const RegionStep>(
      [centres = centres_, r2 = radius_sq_](octomap::OcTree& t, octomap::OcTreeNode* node, unsigned depth,
                                            const octomap::OcTreeKey& min_key) {
        uint64_t visited = 0, deleted = 0;
        return clear_node(t, *centres, r2, node, depth, min_key, visited, deleted);
      });
}

bool DistanceClearingSweep::run_slice(octomap::OcTree& tree, uint64_t node_budget) {
  if (centres_->empty()) return true;  // no robot seen lately: nothing to clear
  return sweep_.run_slice(
      tree, node_budget,
      [this](octomap::OcTree& t, octomap::OcTreeNode* node, unsigned depth, const octomap::OcTreeKey& min_key,
             uint64_t& visited) {
        return clear_node(t, *centres_, radius_sq_, node, depth, min_key, visited, deleted_);
      },
      &stand_ins_);
}

uint64_t clear_beyond(octomap::OcTree& tree, const RegionGrid& grid, std::vector<octomap::point3d> centres,
                      double radius) {
  DistanceClearingSweep sweep(tree, grid, std::move(centres), radius);
  sweep.run_slice(tree, UINT64_MAX);
  return sweep.nodes_deleted();
}

}  // namespace ort
