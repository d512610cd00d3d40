// OctoMap's memoryUsage() without its walk of the whole tree (issue 25): memoryUsage() needs
// the leaf count, a walk of every node, and the memory bound needs the figure exactly each time
// its estimate says the map is past the bound (with the map about the bound, every few scans).
//
// The tally keeps, per region, the inner nodes (nodes with a child) of the region's subtree as
// they were at the last count, and which regions have been changed since. A count walks the
// nodes above the region depth (as the eviction's listing does) and recounts only the subtrees
// of changed regions; every other region's subtree is the one counted before, so the figure
// is exact. Whoever changes nodes at or below the region depth says which regions first
// (octree/region_residency.h does for touches, restores and evictions; its callers for edits
// and sweeps). Why a stale entry can never be read: a region's root may change without a
// change inside the region only by a prune or an expansion above it, and both leave the root a
// leaf, which counts 0 whatever the tally holds.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include <octomap/OcTree.h>

#include "octree/region.h"

namespace ort {

class RegionTally {
 public:
  explicit RegionTally(const RegionGrid& grid) : grid_(grid) {}

  // The subtree of region `id` (or the regions meeting the key box [lo, hi], inclusive) may
  // change or has changed since the last count.
  void changed(RegionId id);
  void changed_box(const octomap::OcTreeKey& lo, const octomap::OcTreeKey& hi);
  // Anything may have changed (a reset, a tree replaced): the next count walks the tree.
  void changed_all();

  // The tree's nodes with a child (tree.size() minus OctoMap's getNumLeafNodes()), exactly.
  uint64_t inner_nodes(const octomap::OcTree& tree);
  // OctoMap's memoryUsage() of `tree`, exactly, from inner_nodes().
  uint64_t memory(const octomap::OcTree& tree);

  // What the counts cost, over the tally's life: regions recounted and reused.
  uint64_t regions_recounted() const { return recounted_; }
  uint64_t regions_reused() const { return reused_; }

 private:
  // More regions than this in one box: everything counts as changed (no long id loop).
  static constexpr uint64_t kMaxBoxRegions = 4096;
  uint64_t count_below(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const octomap::OcTreeKey& min_key,
                       unsigned depth, std::unordered_map<RegionId, uint64_t>& next);

  RegionGrid grid_;
  std::unordered_map<RegionId, uint64_t> inner_;  // regions whose root had a child at the last count
  std::unordered_set<RegionId> changed_;
  bool all_changed_ = true;
  uint64_t recounted_ = 0, reused_ = 0;
};

}  // namespace ort
