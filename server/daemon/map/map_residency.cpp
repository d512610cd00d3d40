#include "daemon/map/map_residency.h"

#include <algorithm>
#include <stdexcept>

#include "daemon/map/map_identity.h"
#include "daemon/map/map_state.h"
#include "octree/region_codec.h"

namespace ort::daemon {

MapResidency::MapResidency(MapState& map, const RegionGrid& grid, RegionSpill& spill, uint64_t max_bytes, Log log)
    : map_(map),
      grid_(grid),
      spill_(spill),
      max_bytes_(max_bytes),
      log_(std::move(log)),
      residency_(grid, spill, max_bytes) {
  stats_.max_bytes = max_bytes;
}

// The one place eviction and restore are counted as a change of the map (its state id,
// through daemon/map/map_identity.h): the map's contents are the same, its tree is not.
void MapResidency::count_residency_change() { count_map_change(map_); }

uint64_t MapResidency::estimate(const octomap::OcTree& tree) const {
  if (bytes_per_node_ <= 0) return tree.memoryUsage();
  return sizeof(octomap::OcTree) + static_cast<uint64_t>(bytes_per_node_ * static_cast<double>(tree.size()));
}

void MapResidency::publish_stats(const octomap::OcTree& tree) {
  const ResidencyStats r = residency_.stats();
  std::lock_guard lock(stats_mutex_);
  stats_.resident_bytes = estimate(tree);
  stats_.resident_regions = resident_regions_;
  stats_.evicted_regions = r.evicted_regions;
  stats_.evicted_bytes = r.evicted_bytes;
  stats_.evictions = r.evictions;
  stats_.restores = r.restores;
}

bool MapResidency::touch_scan(octomap::OcTree& tree, std::span<const VoxelUpdate> voxels, std::string& error) {
  std::lock_guard lock(mutex_);
  const uint64_t before = residency_.stats().restores;
  try {
    residency_.touch_voxels(tree, voxels);
  } catch (const std::exception& e) {
    error = std::string("a region of the scan could not be read back from the region store: ") + e.what();
    if (residency_.stats().restores != before) count_residency_change();
    publish_stats(tree);
    std::lock_guard s(stats_mutex_);
    stats_.restore_failures++;
    stats_.last_error = error;
    return false;
  }
  if (residency_.stats().restores != before) count_residency_change();
  publish_stats(tree);
  return true;
}

void MapResidency::touch_boxes(octomap::OcTree& tree, std::span<const query::KeyBox> boxes) {
  std::lock_guard lock(mutex_);
  std::vector<RegionId> ids;
  for (const query::KeyBox& b : boxes) {
    const std::vector<RegionId> in = residency_.spilled_in(b.min, b.max);
    ids.insert(ids.end(), in.begin(), in.end());
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  if (ids.empty()) return;
  try {
    residency_.touch(tree, ids);
  } catch (const std::exception& e) {
    count_residency_change();
    publish_stats(tree);
    std::lock_guard s(stats_mutex_);
    stats_.restore_failures++;
    stats_.last_error = std::string("restore: ") + e.what();
    throw std::runtime_error(std::string("a region could not be read back from the region store: ") + e.what());
  }
  count_residency_change();
  publish_stats(tree);
}

bool MapResidency::any_spilled_in(std::span<const query::KeyBox> boxes) const {
  std::lock_guard lock(mutex_);
  for (const query::KeyBox& b : boxes)
    if (!residency_.spilled_in(b.min, b.max).empty()) return true;
  return false;
}

void MapResidency::enforce(octomap::OcTree& tree) {
  std::lock_guard lock(mutex_);
  if (estimate(tree) <= max_bytes_) return publish_stats(tree);
  // Over by the estimate: count exactly, then spill down to the low-water mark.
  const uint64_t exact = tree.memoryUsage();
  if (tree.size() > 0) bytes_per_node_ = double(exact - sizeof(octomap::OcTree)) / double(tree.size());
  if (exact > max_bytes_) {
    const auto target = static_cast<uint64_t>(kLowWater * static_cast<double>(max_bytes_));
    const uint64_t before = residency_.stats().evictions;
    EnforceResult r;
    try {
      r = residency_.enforce(tree, exact, target);
    } catch (const std::exception& e) {  // the store refused a put: that region stays here
      std::lock_guard s(stats_mutex_);
      if (stats_.evict_failures++ == 0 || stats_.evict_failures % 1000 == 0)
        log_.warning(text("the region store refused an eviction (", stats_.evict_failures,
                          " so far; the map stays whole in memory, above --max-map-memory): ", e.what()));
      stats_.last_error = std::string("evict: ") + e.what();
    }
    if (r.listed) resident_regions_ = r.listed - r.regions;
    if (residency_.stats().evictions != before) {
      count_residency_change();
      const uint64_t after = tree.memoryUsage();
      if (tree.size() > 0) bytes_per_node_ = double(after - sizeof(octomap::OcTree)) / double(tree.size());
    }
  }
  publish_stats(tree);
}

SweepSpill MapResidency::sweep_hooks() {
  SweepSpill s;
  s.bring_back = [this](octomap::OcTree& tree, RegionId id) {
    std::lock_guard lock(mutex_);
    if (!residency_.spilled(id)) return;
    residency_.bring_back(tree, id);  // throws when the store refuses: the sweep stops there
    count_residency_change();
  };
  s.spilled = [this](RegionId id) {
    std::lock_guard lock(mutex_);
    return residency_.spilled(id);
  };
  return s;
}

void MapResidency::forget_all() {
  std::lock_guard lock(mutex_);
  try {
    residency_.forget_all();
  } catch (const std::exception& e) {  // stale files only: the next start clears the store
    log_.warning(text("the region store kept regions of a map that was reset: ", e.what()));
  }
  resident_regions_ = 0;
  publish_stats(*map_.tree);
}

void MapResidency::fill_copy(octomap::OcTree& copy) const {
  std::lock_guard lock(mutex_);
  const RegionGrid& grid = residency_.grid();
  for (RegionId id : residency_.spilled_ids()) restore_region(copy, grid, id, spill_.get(id));
}

MapResidencyStats MapResidency::stats() const {
  std::lock_guard lock(stats_mutex_);
  return stats_;
}

}  // namespace ort::daemon
