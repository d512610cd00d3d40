// A sweep over a tree's regions in slices of bounded work: the regions are listed when the
// sweep starts, and each slice visits listed regions until it has visited a node budget. A
// caller holding the map lock per slice never stalls for a time that grows with the map.
// Decay (octree/decay.h) and clearing by distance (octree/distance_clearing.h) run on it.
//
// Between slices other updates may run; each listed region is visited once:
// - a region a later update expanded below a coarse leaf is visited whole (the space once);
// - a region that a later update merged into a coarser leaf is skipped (that update wrote
//   the leaf after the sweep began);
// - space first stored after the sweep began waits for the next sweep.
// The nodes above the region depth get their values (max of children) on the path of every
// visited region; they are pruned only when the sweep ends, as OctoMap's prune() does (every
// node but the root), so that no slice merges a visited region with one still to come.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <octomap/OcTree.h>

#include "octree/region.h"

namespace ort {

// What a sweep does to one region: `node` at `depth` (the region's root, or a coarse leaf
// above it) with its min-corner key. Changes the subtree below `node` (deleting children
// with delete_subtree, keeping inner values and pruning below `node` consistent), returns
// true when `node` itself must go. Adds the nodes it visited to `visited`.
using RegionVisit = std::function<bool(octomap::OcTree& tree, octomap::OcTreeNode* node, unsigned depth,
                                       const octomap::OcTreeKey& min_key, uint64_t& visited)>;

// Deletes child `i` of `parent` and its whole subtree, freeing every node and child array,
// with the tree's node counter kept. The parent's own child array stays (even if empty).
void delete_subtree(octomap::OcTree& tree, octomap::OcTreeNode* parent, unsigned i);

// Frees `node`'s child array when no child is left in it (OctoMap's destructor asserts it is
// gone; its own deleteNode leaves it behind).
void free_empty_child_array(octomap::OcTreeNode* node);

// The min-corner key of child `i` of a node at `depth` whose min corner is `min_key`.
octomap::OcTreeKey child_min_key(const octomap::OcTreeKey& min_key, unsigned depth, unsigned i);

// What one sweep does to a region (its root `node` at `depth`, min corner `min_key`), as a
// step that can be kept and applied later: true when `node` must go (the caller deletes it).
using RegionStep = std::function<bool(octomap::OcTree& tree, octomap::OcTreeNode* node, unsigned depth,
                                      const octomap::OcTreeKey& min_key)>;

// What a sweep does to a stand-in (a spilled region, octree/region_residency.h) instead of
// bringing it back: leave it (nothing of it changes), owe it the sweep's step (kept with the
// region and applied, in order, when it comes back; the sweep may set the stand-in's value to
// what its subtree's maximum becomes), or delete it (the whole region goes, unread).
enum class StandInFate { kUnchanged, kOwes, kGone };
struct StandInRule {
  std::function<StandInFate(octomap::OcTree& tree, octomap::OcTreeNode* stand_in, unsigned depth,
                            const octomap::OcTreeKey& min_key)>
      now;
  std::shared_ptr<const RegionStep> owed;  // for kOwes (one for every region the sweep owes it)
  bool prunes = false;                     // the sweep's visit prunes the nodes it leaves (decay does, clearing not)
};

// With a memory bound (octree/region_residency.h) some regions are stand-ins for subtrees on
// disk. A sweep with a StandInRule and the hooks `owe` and `drop` leaves them on disk: it walks
// a sweep region holding stand-ins down to the bound's region depth (`depth`) and visits the
// real nodes there, applying the rule to each stand-in. A sweep without them, or one meeting
// a stand-in that cannot owe more (`can_owe`), brings the sweep region back (`bring_back`)
// before it visits it. Its closing prune leaves alone every node with a stand-in below it.
// `reshaped` hears of every listed region (or coarse leaf: its min-corner key and depth) whose
// visit made or deleted nodes (the bound's memory tally, octree/region_tally.h: a visit that
// only changed values leaves every node's children as they were).
// Ids: `bring_back`, `spilled` and `can_owe` take the sweep's regions; `stand_in`, `owe` and
// `drop` the bound's (at `depth`, as fine as the sweep's or finer).
struct SweepSpill {
  std::function<void(octomap::OcTree&, RegionId)> bring_back;
  std::function<bool(RegionId)> spilled;
  std::function<void(const octomap::OcTreeKey& min_key, unsigned depth)> reshaped;
  unsigned depth = 0;
  std::function<bool(RegionId)> can_owe;
  std::function<bool(RegionId)> stand_in;
  std::function<void(RegionId, const std::shared_ptr<const RegionStep>&)> owe;
  std::function<void(RegionId)> drop;  // the stand-in was deleted from the tree
};

class RegionSweep {
 public:
  RegionSweep(const octomap::OcTree& tree, const RegionGrid& grid);
  void set_spill(SweepSpill spill) { spill_ = std::move(spill); }

  // Visits listed regions until `node_budget` nodes were visited (at least one region) or
  // none is left; then, once, prunes the nodes above the region depth. True when done.
  // `stand_ins`: what the sweep does to spilled regions without bringing them back (null:
  // each comes back before its visit).
  bool run_slice(octomap::OcTree& tree, uint64_t node_budget, const RegionVisit& visit,
                 const StandInRule* stand_ins = nullptr);
  bool done() const { return finished_; }
  size_t regions_left() const { return units_.size() - next_; }
  uint64_t nodes_visited() const { return visited_; }
  uint64_t nodes_deleted() const { return deleted_; }  // region nodes and ancestors left empty
  uint64_t regions_visited() const { return regions_; }
  uint64_t stand_ins_owed() const { return owed_; }  // steps left owed to spilled regions
  uint64_t stand_ins_dropped() const { return dropped_; }

 private:
  struct Unit {
    octomap::OcTreeKey min_key;
    unsigned depth;
  };
  void visit_unit(octomap::OcTree& tree, const Unit& unit, const RegionVisit& visit, const StandInRule* rule);
  void sweep_unit(octomap::OcTree& tree, const Unit& unit, const RegionVisit& visit, const StandInRule* rule);
  // A sweep region holding stand-ins: its real nodes at the bound's depth visited, the rule
  // applied to its stand-ins, the nodes between settled as the visit settles its own.
  bool visit_around(octomap::OcTree& tree, octomap::OcTreeNode* node, unsigned depth, const octomap::OcTreeKey& min_key,
                    const RegionVisit& visit, const StandInRule& rule);

  RegionGrid grid_;
  SweepSpill spill_;
  std::vector<Unit> units_;
  size_t next_ = 0;
  bool finished_ = false;
  uint64_t visited_ = 0, deleted_ = 0, regions_ = 0, owed_ = 0, dropped_ = 0;
};

}  // namespace ort
