// A region sweep (octree/region_sweep.h: decay, clearing by distance) as replayable map steps
// (daemon/map/map_identity.h): each slice is one MapStep, applied to the map of record and
// replayed on the read replica. Every tree the slices run on gets its own sweep, made by its
// first slice: the replica replays the map's changes in the map's order, so its sweep starts
// at the same map state as the map of record's, lists the same regions and does the same in
// every slice (tests/server/map_upkeep_test.cpp compares the replica with the rule's map).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <utility>

#include <octomap/OcTree.h>

#include "daemon/map/map_identity.h"

namespace ort::daemon {

template <class Sweep>
class SweepSlices {
 public:
  // Makes the sweep for a tree at the state of its first slice.
  using Make = std::function<std::unique_ptr<Sweep>(const octomap::OcTree&)>;

  // The steps of one sweep: each call of the returned step runs the next slice (at most
  // `slice_nodes` visited nodes) of the sweep of the tree it is given.
  static std::pair<std::shared_ptr<SweepSlices>, MapStep> steps(Make make, uint64_t slice_nodes) {
    auto self = std::shared_ptr<SweepSlices>(new SweepSlices(std::move(make), slice_nodes));
    return {self, [self](octomap::OcTree& tree) { self->run_slice(tree); }};
  }

  // The sweep of `tree`, or null before its first slice.
  const Sweep* on(const octomap::OcTree& tree) const {
    std::lock_guard lock(mutex_);
    const auto it = sweeps_.find(&tree);
    return it == sweeps_.end() ? nullptr : it->second.get();
  }

 private:
  SweepSlices(Make make, uint64_t slice_nodes) : make_(std::move(make)), slice_nodes_(slice_nodes) {}

  // The map of record's slices run on the upkeep thread, the replica's on the replica's
  // thread: each under its own tree's lock, the table of sweeps under this one.
  void run_slice(octomap::OcTree& tree) {
    Sweep* sweep = nullptr;
    {
      std::lock_guard lock(mutex_);
      std::unique_ptr<Sweep>& s = sweeps_[&tree];
      if (!s) s = make_(tree);
      sweep = s.get();
    }
    if (!sweep->done()) sweep->run_slice(tree, slice_nodes_);
  }

  Make make_;
  uint64_t slice_nodes_;
  mutable std::mutex mutex_;
  std::map<const octomap::OcTree*, std::unique_ptr<Sweep>> sweeps_;
};

}  // namespace ort::daemon
