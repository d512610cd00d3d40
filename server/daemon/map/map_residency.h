// The memory bound in the daemon (--max-map-memory, issue 25): past the bound, the regions
// least recently touched leave the tree for the region store (octree/region_residency.h) and
// come back before anything reads or changes them, so the map is the same map as without
// the bound, voxel for voxel:
// - stage 2 touches a scan's regions before its update and enforces the bound after it;
// - edits touch their box (a reset drops every spilled region);
// - queries touch what they may read (daemon/queries/query_footprint.h), under the
//   exclusive lock when something must come back;
// - the upkeep's sweeps bring each spilled region back before they visit it;
// - whole-map readers (snapshots, saves, the OCTOMAP map) fill their copy's stand-ins from
//   the store (fill_copy), so every snapshot and save is the whole map.
// Every batch of evictions or restores counts as one map change (count_residency_change).
//
// Memory is counted as OctoMap's memoryUsage() counts it: the tree is walked only when the
// running estimate (nodes times the bytes a node took at the last walk) passes the bound;
// eviction then goes down to kLowWater of the bound so that it runs every few scans, not
// every scan.
#pragma once

#include <cstdint>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "core/log.h"
#include "core/voxel_update.h"
#include "octree/region_residency.h"
#include "octree/region_sweep.h"
#include "query/key_box.h"

namespace ort::daemon {

struct MapState;

struct MapResidencyStats {
  uint64_t max_bytes = 0;
  uint64_t resident_bytes = 0;                      // the tree's memory (estimate between walks)
  uint64_t resident_regions = 0;                    // regions holding a subtree at the last eviction pass
  uint64_t evicted_regions = 0, evicted_bytes = 0;  // now, in the store
  uint64_t evictions = 0, restores = 0;             // over the run
  uint64_t evict_failures = 0, restore_failures = 0;
  std::string last_error;  // the store's last refusal ("" if none)
};

class MapResidency {
 public:
  // Eviction back to this fraction of the bound.
  static constexpr double kLowWater = 0.9;

  MapResidency(MapState& map, const RegionGrid& grid, RegionSpill& spill, uint64_t max_bytes, Log log);

  // Under the exclusive map lock. Brings back the scan's regions; false (with `error`) when
  // the store could not give one back: the scan must not be applied (its region would be
  // updated as a coarse leaf).
  bool touch_scan(octomap::OcTree& tree, std::span<const VoxelUpdate> voxels, std::string& error);
  // Under the exclusive map lock: brings back every region meeting the boxes (queries, edits).
  // Throws RegionStoreError-like std::runtime_error when the store refuses.
  void touch_boxes(octomap::OcTree& tree, std::span<const query::KeyBox> boxes);
  // Under the map lock (shared is enough): whether a box meets a spilled region.
  bool any_spilled_in(std::span<const query::KeyBox> boxes) const;
  // Under the exclusive map lock, after a change: spills past the bound. Never throws: a store
  // that refuses keeps the regions in memory (counted, logged).
  void enforce(octomap::OcTree& tree);
  // A sweep's hooks (octree/region_sweep.h): call under the exclusive map lock.
  SweepSpill sweep_hooks();
  // Under the exclusive map lock: the map was emptied (a reset).
  void forget_all();
  // Under the map lock (shared is enough): puts every spilled region into `copy`, a copy of
  // the map's tree, which then is the whole map. Throws when the store cannot give one back.
  void fill_copy(octomap::OcTree& copy) const;

  MapResidencyStats stats() const;
  const RegionGrid& grid() const { return grid_; }

 private:
  void count_residency_change();
  uint64_t estimate(const octomap::OcTree& tree) const;

  MapState& map_;
  RegionGrid grid_;
  RegionSpill& spill_;
  uint64_t max_bytes_;
  Log log_;
  void publish_stats(const octomap::OcTree& tree);

  // residency_ and the spill (shared-lock readers fill copies at the same time).
  mutable std::mutex mutex_;
  RegionResidency residency_;
  double bytes_per_node_ = 0;  // at the last walk
  uint64_t resident_regions_ = 0;
  // What stats() reports, behind its own lock: the status never waits for a spill.
  mutable std::mutex stats_mutex_;
  MapResidencyStats stats_;
};

}  // namespace ort::daemon
