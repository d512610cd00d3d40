// Decay: forgetting what is no longer seen. One decay step moves every stored leaf's
// log-odds toward 0 (unknown) by one factor; a leaf that ends closer to 0 than a threshold
// is deleted and its memory freed. The rule, exactly (docs/ARCHITECTURE.md, "Decay"):
//
//   for every stored leaf (finest or pruned):  L <- fl(L * factor)        (float multiply)
//   |L| < delete_below                       :  the leaf is deleted
//   an inner node left without children      :  deleted too (up to the root: an empty tree)
//   every inner node                         :  max of its children's log-odds (OctoMap's
//                                               updateInnerOccupancy)
//   8 leaf children of equal log-odds        :  pruned into their parent (OctoMap's prune:
//                                               every node but the root)
//
// The same tree and the same steps give the same tree, bit for bit: the multiply is per leaf
// and order-free, and the result is what OctoMap's own tree would hold after setting every
// leaf, updateInnerOccupancy() and prune() (the test builds it that way).
//
// A sweep applies one step region by region (octree/region.h) in slices of bounded work, so
// a caller holding the map lock per slice never stalls for a time that grows with the map.
// Between slices other updates may run; the regions of a sweep are listed when it starts,
// and each is decayed once by it:
// - a region a later update expanded below a coarse leaf is decayed whole (the space once);
// - a region that a later update merged into a coarser leaf is skipped by this sweep (the
//   update wrote that leaf's value after the sweep began);
// - space first stored after the sweep began waits for the next sweep.
// Nodes above the region depth are pruned at the end of the sweep, not per slice, so that
// no slice merges a decayed region with one still to come.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <octomap/OcTree.h>

#include "octree/region.h"

namespace ort {

struct DecayRule {
  float factor = 1.0f;        // per step, in (0, 1]
  float delete_below = 0.1f;  // |log-odds| below this after the step: deleted
};

// The factor of a step `step_s` seconds long with half-life `half_life_s` (> 0):
// float(2^(-step_s / half_life_s)). Throws std::invalid_argument for a non-positive or
// non-finite half-life or a negative or non-finite step.
float decay_factor(double step_s, double half_life_s);

struct DecayStats {
  uint64_t nodes_visited = 0;
  uint64_t leaves_decayed = 0;
  uint64_t nodes_deleted = 0;  // leaves below the threshold and inner nodes left empty
  uint64_t regions = 0;        // regions decayed
};

// Deletes child `i` of `parent` and its whole subtree, freeing every node and child array,
// with the tree's node counter kept. The parent's own child array stays (even if empty).
void delete_subtree(octomap::OcTree& tree, octomap::OcTreeNode* parent, unsigned i);

// Frees `node`'s child array when no child is left in it (OctoMap's destructor asserts it is
// gone; its own deleteNode leaves it behind).
void free_empty_child_array(octomap::OcTreeNode* node);

class DecaySweep {
 public:
  // Lists the regions of `tree` to decay by `rule`.
  DecaySweep(const octomap::OcTree& tree, const RegionGrid& grid, const DecayRule& rule);

  // Decays listed regions until `node_budget` nodes were visited (at least one region) or
  // none is left; then, once, prunes the nodes above the region depth. True when the sweep
  // is done. The tree must be the one listed (changed by other updates in between is fine).
  bool run_slice(octomap::OcTree& tree, uint64_t node_budget);
  bool done() const { return finished_; }
  const DecayStats& stats() const { return stats_; }
  size_t regions_left() const { return units_.size() - next_; }

 private:
  struct Unit {
    octomap::OcTreeKey min_key;
    unsigned depth;
  };
  void decay_unit(octomap::OcTree& tree, const Unit& unit);

  RegionGrid grid_;
  DecayRule rule_;
  std::vector<Unit> units_;
  size_t next_ = 0;
  bool finished_ = false;
  DecayStats stats_;
};

// One whole step at once (a sweep with no slice limit).
DecayStats decay_tree(octomap::OcTree& tree, const RegionGrid& grid, const DecayRule& rule);

}  // namespace ort
