// The memory bound in the daemon (--max-map-memory, issue 25): past the bound, the regions
// least recently touched leave the tree for the region store (octree/region_residency.h) and
// come back before anything reads or changes them, so the map is the same map as without
// the bound, voxel for voxel:
// - stage 2 touches a scan's regions before its update and enforces the bound after it;
// - edits touch their box (a reset drops every spilled region);
// - queries touch what they may read (daemon/queries/query_footprint.h), under the
//   exclusive lock when something must come back;
// - the upkeep's sweeps leave spilled regions on disk: each owes the sweep's step, applied
//   when it comes back, or goes unread when the step deletes all of it (region_sweep.h);
// - whole-map readers (snapshots, saves, the OCTOMAP map) fill their copy's stand-ins from
//   the store (fill_copy), so every snapshot and save is the whole map.
// Every batch of evictions or restores counts as one map change (count_residency_change).
//
// Memory is counted as OctoMap's memoryUsage() counts it: exactly (octree/region_tally.h:
// the nodes above the region depth and the regions changed since the last count are walked)
// when the running estimate (nodes times the bytes a node took at the last count) passes the bound;
// eviction then goes down to kLowWater of the bound. Between kSoftStart and the bound each
// change spills one idle sibling group (none touched within the working set's T seconds:
// octree/residency/working_set_window.h) by the estimate alone (no walk), so the map rarely
// gets there: the cost is spread over the scans (docs/BENCHMARKS.md "The memory bound").
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <octomap/OcTree.h>

#include "core/clock.h"
#include "core/log.h"
#include "core/voxel_update.h"
#include "daemon/map/subtree_reaper.h"
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
  uint64_t steps_owed = 0, dropped = 0;             // over the run: sweeps' steps kept, regions deleted unread
  uint64_t owed_now = 0;                            // steps kept now
  uint64_t evict_failures = 0, restore_failures = 0;
  uint64_t hot_overshoots = 0;  // passes past the bound that left it above (every region left was in use)
  std::string last_error;       // the store's last refusal ("" if none)
  // Where the time goes, over the run (ms): the passes that evict, the exact memory walks
  // they start with, the scans' restores, and the octree layer's parts of both.
  uint64_t enforce_passes = 0;
  double enforce_ms = 0, walk_ms = 0, touch_ms = 0;
  double max_enforce_ms = 0, max_touch_ms = 0;          // since the last cost line
  double longest_enforce_ms = 0, longest_touch_ms = 0;  // since start
  ResidencyCosts costs;
  uint64_t regions_recounted = 0, regions_reused = 0;  // by the exact counts (octree/region_tally.h)
};

// One line saying where the bound's time went between `before` and `now` (the daemon logs it
// every kCostReportS seconds while the bound works; the benchmarks read it).
std::string residency_cost_line(const MapResidencyStats& before, const MapResidencyStats& now);

class MapResidency {
 public:
  // Past kSoftStart of the bound (by the running estimate), each change spills one sibling
  // group (the least recently touched), so eviction is spread over the scans instead of one
  // long pass; past the bound itself (counted exactly) it spills down to kLowWater at once.
  static constexpr double kSoftStart = 0.95;
  static constexpr double kLowWater = 0.9;
  // The most one change's eviction pass takes (ms) once the map is within the bound: it
  // stops between two sibling groups, and the next change goes on down to kLowWater. The way
  // back to the bound itself is never cut. Eviction only counts and detaches nodes (the
  // writer thread encodes and stores them).
  static constexpr double kSliceMs = 3;
  // Between kSoftStart and the bound only regions outside the working set (none of the group
  // touched in the last T seconds: octree/residency/working_set_window.h) go: spilling what
  // the robots are mapping only to bring it back a scan later is all cost and no room (past
  // kHotOvershoot the regions in use go too, below).
  // Past the bound the idle groups go first; when only regions in use are left the map stays
  // above the bound, up to kHotOvershoot of it, rather than spill what the next scans bring
  // back (the soak's ping-pong, docs/BENCHMARKS.md 'Memory bound'); past that they go too,
  // back to the bound.
  static constexpr double kHotOvershoot = 1.10;
  // How often the cost breakdown is logged while regions move.
  static constexpr double kCostReportS = 10;

  // `working_set_s` (--working-set-seconds): the working set's T; 0: it follows the scan rate.
  MapResidency(MapState& map, const RegionGrid& grid, RegionSpill& spill, uint64_t max_bytes, Log log,
               double working_set_s = 0);

  // Under the exclusive map lock. Brings back the scan's regions; false (with `error`) when
  // the store could not give one back: the scan must not be applied (its region would be
  // updated as a coarse leaf). `robot` (the scan's robot id) feeds the working set's rate.
  bool touch_scan(octomap::OcTree& tree, std::span<const VoxelUpdate> voxels, std::string& error,
                  std::string_view robot = {});
  // Replaces the working set's window (a fixed T, a test's clock); before the first scan.
  void set_working_set(WorkingSetWindow w);
  // The working set's T now, in seconds.
  double working_set_seconds() const;
  // Under the exclusive map lock: brings back every region meeting the boxes (queries, edits).
  // Throws RegionStoreError-like std::runtime_error when the store refuses.
  void touch_boxes(octomap::OcTree& tree, std::span<const query::KeyBox> boxes);
  // Under the exclusive map lock, before an edit changes the boxes (the exact memory count,
  // octree/region_tally.h, recounts them).
  void will_change(std::span<const query::KeyBox> boxes);
  // Under the map lock (shared is enough): whether a box meets a spilled region.
  bool any_spilled_in(std::span<const query::KeyBox> boxes) const;
  // Under the exclusive map lock, after a change: spills past the bound. Never throws: a store
  // that refuses keeps the regions in memory (counted, logged).
  void enforce(octomap::OcTree& tree);
  // A sweep's hooks (octree/region_sweep.h) for a sweep over `sweep` regions, as coarse as the
  // bound's or coarser: spilled regions owe the sweep's step or go unread; one that owes
  // too many comes back (with the rest of its sweep region) before the sweep visits it. A
  // sweep region counts as spilled while any region inside it is. Call under the exclusive
  // map lock.
  SweepSpill sweep_hooks(const RegionGrid& sweep);
  // While the map is loaded, before anything reads it: region `id` of the map file goes to the
  // store as `bytes` and is a stand-in in the tree being built (daemon/persistence/map_store.h
  // MapLoadBound). Throws when the store refuses (the server then does not start).
  void adopt_loaded(RegionId id, std::span<const uint8_t> bytes);
  // Under the exclusive map lock: the map was emptied (a reset).
  void forget_all();
  // Under the map lock (shared is enough): the bytes of every spilled region, read from the
  // store, which put into a copy of the map's tree taken under the same lock (fill_copy, after
  // the lock is let go: the rebuild costs no one a wait) make it the whole map. Throws when
  // the store cannot give one back.
  // With each region the sweeps' steps it owes (octree/region_residency.h owe), which the copy
  // applies once its bytes are in.
  struct SpilledRegion {
    RegionId id = 0;
    std::vector<uint8_t> bytes;
    std::vector<std::shared_ptr<const RegionStep>> owed;
  };
  using SpilledRegions = std::vector<SpilledRegion>;
  SpilledRegions spilled_regions() const;
  static void fill_copy(octomap::OcTree& copy, const RegionGrid& grid, const SpilledRegions& regions);

  MapResidencyStats stats() const;
  const RegionGrid& grid() const { return grid_; }

 private:
  void count_residency_change();
  // enforce() with mutex_ held; `exact`: counts the memory exactly whatever the estimate says.
  void enforce_locked(octomap::OcTree& tree, bool exact = false);
  uint64_t estimate(const octomap::OcTree& tree) const;

  MapState& map_;
  RegionGrid grid_;
  uint64_t max_bytes_;
  Log log_;
  void publish_stats(const octomap::OcTree& tree);
  // Adds a touch's or an enforce pass's time to the stats; logs the breakdown now and then.
  void note_costs(double touch_ms, double enforce_ms, double walk_ms);

  // residency_ and the spill (shared-lock readers fill copies at the same time).
  mutable std::mutex mutex_;
  SubtreeReaper reaper_;  // frees evicted regions' nodes off the map lock (before residency_: outlives its hook)
  RegionResidency residency_;
  double bytes_per_node_ = 0;  // at the last walk
  uint64_t resident_regions_ = 0;
  // What stats() reports, behind its own lock: the status never waits for a spill.
  mutable std::mutex stats_mutex_;
  MapResidencyStats stats_;
  MapResidencyStats reported_;  // at the last cost line
  SteadyClock::time_point reported_at_ = SteadyClock::now();
};

}  // namespace ort::daemon
