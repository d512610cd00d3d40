// Clearing by distance (nvblox's map_clearing_radius_m habit): everything farther than a
// radius from every one of a set of centres (the robots seen lately) is deleted and freed.
// The rule: a stored leaf (finest or pruned) is deleted when its whole cube lies farther
// than `radius` from every centre (Euclidean distance from the centre to the nearest point
// of the cube); a leaf that reaches within the radius is kept whole. Inner nodes left
// without children go too, the others hold the max of their children (OctoMap's
// updateInnerOccupancy). No centre: nothing is cleared. Applied region by region in slices
// (octree/region_sweep.h); whole regions wholly beyond the radius go in one step. A spilled
// region (a memory bound's stand-in) is never brought back for it: one wholly beyond goes
// from the store unread, one wholly within is kept as it is, one across the radius is owed
// the clearing, applied when it comes back.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <octomap/OcTree.h>

#include "octree/region.h"
#include "octree/region_sweep.h"

namespace ort {

class DistanceClearingSweep {
 public:
  // Throws std::invalid_argument for a radius that is not a positive finite number.
  DistanceClearingSweep(const octomap::OcTree& tree, const RegionGrid& grid, std::vector<octomap::point3d> centres,
                        double radius);
  bool run_slice(octomap::OcTree& tree, uint64_t node_budget);
  // The sweep under it (a memory bound's hooks: RegionSweep::set_spill).
  RegionSweep& regions() { return sweep_; }
  bool done() const { return centres_->empty() || sweep_.done(); }
  uint64_t nodes_deleted() const { return deleted_ + sweep_.nodes_deleted(); }
  uint64_t nodes_visited() const { return sweep_.nodes_visited(); }

 private:
  RegionSweep sweep_;
  std::shared_ptr<const std::vector<octomap::point3d>> centres_;
  double radius_sq_;
  uint64_t deleted_ = 0;
  StandInRule stand_ins_;
};

// The whole clearing at once.
uint64_t clear_beyond(octomap::OcTree& tree, const RegionGrid& grid, std::vector<octomap::point3d> centres,
                      double radius);

}  // namespace ort
