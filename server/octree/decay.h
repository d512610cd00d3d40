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
// A sweep applies one step region by region in slices of bounded work
// (octree/region_sweep.h, which says what an update between two slices does to it). A
// spilled region (a memory bound's stand-in) is owed the step: it is applied to the region,
// after the steps owed before it, when the region comes back (the per-leaf rule gives the
// same leaves whenever it runs; the stand-in's value meanwhile is its subtree's maximum times
// the factor, what the maximum becomes unless the step deletes that leaf).
#pragma once

#include <cstddef>
#include <cstdint>

#include <octomap/OcTree.h>

#include "octree/region.h"
#include "octree/region_sweep.h"

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

// One step as a sweep in slices.
class DecaySweep {
 public:
  DecaySweep(const octomap::OcTree& tree, const RegionGrid& grid, const DecayRule& rule);
  // RegionSweep::run_slice with the decay: true when the step is done.
  bool run_slice(octomap::OcTree& tree, uint64_t node_budget);
  // The sweep under it (a memory bound's hooks: RegionSweep::set_spill).
  RegionSweep& regions() { return sweep_; }
  bool done() const { return sweep_.done(); }
  DecayStats stats() const;
  uint64_t nodes_deleted() const { return stats().nodes_deleted; }

 private:
  RegionSweep sweep_;
  DecayRule rule_;
  StandInRule stand_ins_;
  uint64_t leaves_decayed_ = 0, leaves_deleted_ = 0;
};

// One step applied to the subtree of `node` at `depth` (a region's root): true when `node`
// must go (every leaf below it was deleted). What a spilled region owes, applied on its return.
bool decay_subtree(octomap::OcTree& tree, octomap::OcTreeNode* node, unsigned depth, const DecayRule& rule);

// One whole step at once (a sweep with no slice limit).
DecayStats decay_tree(octomap::OcTree& tree, const RegionGrid& grid, const DecayRule& rule);

}  // namespace ort
