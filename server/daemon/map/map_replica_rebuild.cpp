// The read replica's rebuild after it fell behind (daemon/map/map_replica.h, "Falling
// behind"): the fall, its slices, and the regions stage 2 notes meanwhile.
#include <algorithm>
#include <shared_mutex>
#include <string>

#include "core/clock.h"
#include "daemon/map/map_replica.h"
#include "octree/versions/region_sync.h"

namespace ort::daemon {

void MapReplica::fall_behind_locked(Item item) {
  stats_.fell_behind++;
  stats_.dropped_items += queue_.size();
  stats_.behind_reason = std::to_string(queue_.size()) + " changes (" + std::to_string(stats_.pending_bytes) +
                         " bytes) not applied yet and " + std::to_string(item.bytes) +
                         " more would pass the bound of " + std::to_string(max_pending_bytes_) +
                         " bytes: rebuilding from the map of record";
  for (Item& it : queue_) dropped_.push_back(std::move(it));
  dropped_.push_back(std::move(item));
  queue_.clear();
  stats_.pending_items = stats_.pending_bytes = 0;
  drops_++;
  behind_ = stats_.behind = true;
  all_dirty_ = true;
  dirty_.clear();
  work_.notify_one();
  progress_.notify_all();  // readers waiting for it read the map of record now
}

void MapReplica::mark_dirty_locked(const Item& item) {
  if (all_dirty_) return;
  if (item.whole()) {
    all_dirty_ = true;
    dirty_.clear();
    return;
  }
  const RegionGrid grid = region_grid(kRebuildRegionDepth);
  // A scan's list keeps neighbouring voxels together: most keys share the region before them.
  bool any = false;
  RegionId last = 0;
  for (const VoxelUpdate& v : item.voxels) {
    const RegionId id = region_of(grid, v.key());
    if (any && id == last) continue;
    dirty_.insert(id);
    any = true;
    last = id;
  }
}

double MapReplica::rebuild_slice() {
  const RegionGrid grid = region_grid(kRebuildRegionDepth);
  const auto t0 = SteadyClock::now();
  // Stage 2 changes the map of record and notes what it changed under the map's exclusive
  // lock: while this shared one is held, the map and the set of changed regions agree.
  std::shared_lock record(record_.mutex);
  const MapHoldNote note(record_.holders, "replica rebuild (slice)");
  std::unordered_set<RegionId> dirty;
  bool all = false;
  {
    std::lock_guard lock(mutex_);
    dirty.swap(dirty_);
    all = all_dirty_;
    all_dirty_ = false;
  }
  const octomap::OcTree& src = *record_.tree;
  if (!rebuild_tree_) rebuild_tree_ = empty_tree_like(src);
  if (all)
    for (RegionId id : list_regions(src, grid)) dirty.insert(id);
  const RegionSyncSlice slice = sync_slice(src, *rebuild_tree_, grid, dirty, rebuild_slice_nodes_);
  std::lock_guard lock(mutex_);
  dirty_.insert(dirty.begin(), dirty.end());  // those left for the next slice
  if (slice.done) {
    // Equal to the map of record at its state now: the replica's thread takes it as its next
    // change; scans after it queue behind it as before the fall.
    Item it;
    it.tree = std::move(rebuild_tree_);
    it.version = record_.version;
    it.epoch = record_.epoch;
    it.scans = record_.scans;
    it.last_scan_utime = record_.last_scan_utime;
    it.newest_all = record_.newest_scan;
    it.leaves = record_.leaves.load(std::memory_order_relaxed);
    it.bytes = sizeof(Item);
    record_version_.store(it.version, std::memory_order_release);
    stats_.pending_items++;
    stats_.pending_bytes += it.bytes;
    queue_.push_back(std::move(it));
    behind_ = stats_.behind = false;
    dirty_.clear();
    stats_.rebuilds_done++;
  }
  const double held = ms_since(t0);
  stats_.rebuild_slices++;
  stats_.rebuild_regions_copied += slice.regions_copied;
  stats_.rebuild_nodes_copied += slice.nodes_copied;
  stats_.rebuild_hold_ms_total += held;
  stats_.rebuild_hold_ms_max = std::max(stats_.rebuild_hold_ms_max, held);
  return held;
}

}  // namespace ort::daemon
