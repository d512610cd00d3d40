#include "daemon/map/map_residency.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <type_traits>

#include "daemon/map/map_identity.h"
#include "daemon/map/map_state.h"
#include "octree/region_codec.h"

namespace ort::daemon {

MapResidency::MapResidency(MapState& map, const RegionGrid& grid, RegionSpill& spill, uint64_t max_bytes, Log log,
                           double working_set_s)
    : map_(map),
      grid_(grid),
      max_bytes_(max_bytes),
      log_(std::move(log)),
      // What waits to be freed: at most about a quarter of the bound (OctoMap's bytes a node).
      reaper_(std::max<uint64_t>(uint64_t(1) << 16, max_bytes / 4 / sizeof(octomap::OcTreeNode))),
      residency_(grid, spill, max_bytes) {
  stats_.max_bytes = max_bytes;
  residency_.set_working_set(WorkingSetWindow(working_set_s));
  residency_.set_free_later([this](DetachedSubtree d) { reaper_.push(d); });
  // Encoding and the store's writes go to the residency's writer thread: an eviction on
  // stage 2 only counts and detaches a region's nodes. As many may wait as the reaper holds.
  residency_.start_background_writes(
      std::max<uint64_t>(uint64_t(1) << 16, max_bytes / 4 / sizeof(octomap::OcTreeNode)));
}

// The one place eviction and restore are counted as a change of the map (its state id,
// through daemon/map/map_identity.h): the map's contents are the same, its tree is not.
void MapResidency::count_residency_change() { count_map_change(map_); }

uint64_t MapResidency::estimate(const octomap::OcTree& tree) const {
  // Before the first exact count: every node as an inner one (an upper bound). Never counted
  // here: a count between a touch and its change would take the touched regions as unchanged.
  const double per_node =
      bytes_per_node_ > 0 ? bytes_per_node_ : double(tree.memoryUsageNode() + sizeof(octomap::OcTreeNode* [8]));
  return sizeof(octomap::OcTree) + static_cast<uint64_t>(per_node * static_cast<double>(tree.size()));
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
  stats_.steps_owed = r.steps_owed;
  stats_.dropped = r.dropped;
  stats_.owed_now = r.owed_now;
  stats_.costs = r.costs;
  stats_.regions_recounted = residency_.tally().regions_recounted();
  stats_.regions_reused = residency_.tally().regions_reused();
}

void MapResidency::note_costs(double touch_ms, double enforce_ms, double walk_ms) {
  std::string line;
  {
    std::lock_guard lock(stats_mutex_);
    if (enforce_ms > 0) {
      stats_.enforce_passes++;
      stats_.enforce_ms += enforce_ms;
      stats_.walk_ms += walk_ms;
      stats_.max_enforce_ms = std::max(stats_.max_enforce_ms, enforce_ms);
      stats_.longest_enforce_ms = std::max(stats_.longest_enforce_ms, enforce_ms);
    }
    stats_.touch_ms += touch_ms;
    stats_.max_touch_ms = std::max(stats_.max_touch_ms, touch_ms);
    stats_.longest_touch_ms = std::max(stats_.longest_touch_ms, touch_ms);
    if (seconds_since(reported_at_) < kCostReportS) return;
    if (stats_.evictions != reported_.evictions || stats_.restores != reported_.restores)
      line = residency_cost_line(reported_, stats_);
    reported_ = stats_;
    reported_.max_enforce_ms = reported_.max_touch_ms = 0;
    stats_.max_enforce_ms = stats_.max_touch_ms = 0;  // maxima per report
    reported_at_ = SteadyClock::now();
  }
  if (!line.empty()) log_.info(line);
}

std::string residency_cost_line(const MapResidencyStats& a, const MapResidencyStats& b) {
  const ResidencyCosts &x = a.costs, &y = b.costs;
  char line[1024];
  std::snprintf(
      line, sizeof line,
      "memory bound costs: %llu passes evicted %llu regions in %.1f ms (most %.1f ms a pass; walks %.1f, "
      "list %.1f, encode %.1f, store write %.1f, strip %.1f); %llu restores in %.1f ms (most %.1f ms a "
      "scan; store read %.1f, rebuild %.1f); exact counts recounted %llu regions, reused %llu; off stage: "
      "sizing %.1f ms, waits for the writer %.1f ms, %llu restores from kept nodes; sweeps over the store: %llu "
      "steps owed, %llu regions deleted unread; %llu passes left the map above the bound (its regions in use)",
      (unsigned long long)(b.enforce_passes - a.enforce_passes), (unsigned long long)(b.evictions - a.evictions),
      b.enforce_ms - a.enforce_ms, b.max_enforce_ms, b.walk_ms - a.walk_ms, y.list_ms - x.list_ms,
      y.encode_ms - x.encode_ms, y.put_ms - x.put_ms, y.strip_ms - x.strip_ms,
      (unsigned long long)(b.restores - a.restores), b.touch_ms - a.touch_ms, b.max_touch_ms, y.get_ms - x.get_ms,
      y.rebuild_ms - x.rebuild_ms, (unsigned long long)(b.regions_recounted - a.regions_recounted),
      (unsigned long long)(b.regions_reused - a.regions_reused), y.size_ms - x.size_ms,
      y.write_wait_ms - x.write_wait_ms, (unsigned long long)(y.reattached - x.reattached),
      (unsigned long long)(b.steps_owed - a.steps_owed), (unsigned long long)(b.dropped - a.dropped),
      (unsigned long long)(b.hot_overshoots - a.hot_overshoots));
  return line;
}

void MapResidency::set_working_set(WorkingSetWindow w) {
  std::lock_guard lock(mutex_);
  residency_.set_working_set(std::move(w));
}

double MapResidency::working_set_seconds() const {
  std::lock_guard lock(mutex_);
  return residency_.working_set().seconds();
}

bool MapResidency::touch_scan(octomap::OcTree& tree, std::span<const VoxelUpdate> voxels, std::string& error,
                              std::string_view robot) {
  std::lock_guard lock(mutex_);
  const auto t0 = SteadyClock::now();
  residency_.working_set().scan(robot);
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
  if (residency_.stats().restores != before) {
    count_residency_change();
    // Restores can take the tree past the bound before the update adds to it: room is made
    // now (the scan's regions, just touched, go last), so the map stays near the bound at
    // every moment, not only after the scan. The count that pass makes took the scan's
    // regions as counted: they are touched again (nothing to restore unless the pass took
    // one), so the update's changes to them are recounted.
    const double touch_ms = ms_since(t0);
    // The estimate (bytes a node at the last count) can miss what restored regions weigh:
    // near the bound, the count decides.
    if (estimate(tree) > static_cast<uint64_t>(kSoftStart * static_cast<double>(max_bytes_))) {
      enforce_locked(tree, /*exact=*/true);
      try {
        residency_.touch_voxels(tree, voxels);
      } catch (const std::exception& e) {
        error = std::string("a region of the scan could not be read back from the region store: ") + e.what();
        publish_stats(tree);
        std::lock_guard s(stats_mutex_);
        stats_.restore_failures++;
        stats_.last_error = error;
        return false;
      }
    }
    publish_stats(tree);
    note_costs(touch_ms, 0, 0);
    return true;
  }
  publish_stats(tree);
  note_costs(ms_since(t0), 0, 0);
  return true;
}

void MapResidency::touch_boxes(octomap::OcTree& tree, std::span<const query::KeyBox> boxes) {
  std::lock_guard lock(mutex_);
  auto spilled_in_boxes = [&] {
    std::vector<RegionId> ids;
    for (const query::KeyBox& b : boxes) {
      const std::vector<RegionId> in = residency_.spilled_in(b.min, b.max);
      ids.insert(ids.end(), in.begin(), in.end());
    }
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    return ids;
  };
  std::vector<RegionId> ids = spilled_in_boxes();
  if (ids.empty()) return;
  const auto t0 = SteadyClock::now();
  try {
    residency_.touch(tree, ids);
    // As a scan's (touch_scan): room is made before the query reads, the regions just
    // touched going last; whatever of the boxes that pass took comes back.
    if (estimate(tree) > static_cast<uint64_t>(kSoftStart * static_cast<double>(max_bytes_))) {
      enforce_locked(tree, /*exact=*/true);
      ids = spilled_in_boxes();
      if (!ids.empty()) residency_.touch(tree, ids);
    }
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
  note_costs(ms_since(t0), 0, 0);
}

void MapResidency::will_change(std::span<const query::KeyBox> boxes) {
  std::lock_guard lock(mutex_);
  for (const query::KeyBox& b : boxes) residency_.changed_box(b.min, b.max);
}

bool MapResidency::any_spilled_in(std::span<const query::KeyBox> boxes) const {
  std::lock_guard lock(mutex_);
  for (const query::KeyBox& b : boxes)
    if (!residency_.spilled_in(b.min, b.max).empty()) return true;
  return false;
}

void MapResidency::enforce(octomap::OcTree& tree) {
  std::lock_guard lock(mutex_);
  enforce_locked(tree);
}

void MapResidency::enforce_locked(octomap::OcTree& tree, bool exact) {
  const uint64_t estimated = estimate(tree);
  const auto soft = static_cast<uint64_t>(kSoftStart * static_cast<double>(max_bytes_));
  if (estimated <= soft && !exact) return publish_stats(tree);
  const auto target = static_cast<uint64_t>(kLowWater * static_cast<double>(max_bytes_));
  const auto t0 = SteadyClock::now();
  double walk_ms = 0;
  uint64_t bytes = estimated;
  size_t groups = 1;  // between the soft start and the bound: one sibling group a change
  if (exact || estimated > max_bytes_ || bytes_per_node_ <= 0) {
    // Over by the estimate: count exactly (the tally recounts only what changed since its
    // last count), and go down to the low-water mark at once.
    bytes = residency_.memory(tree);
    walk_ms = ms_since(t0);
    if (tree.size() > 0) bytes_per_node_ = double(bytes - sizeof(octomap::OcTree)) / double(tree.size());
    groups = bytes > max_bytes_ ? SIZE_MAX : 1;
  }
  if (bytes > soft) {
    const uint64_t before = residency_.stats().evictions;
    size_t listed = 0, regions = 0;
    try {
      // Idle groups first, whichever side of the bound (to the low-water mark past it).
      const EnforceResult idle =
          residency_.enforce(tree, bytes, groups == 1 ? soft : target, groups, kSliceMs, /*idle_only=*/true);
      listed = idle.listed;
      regions = idle.regions;
      const uint64_t left = bytes - std::min(bytes, idle.bytes_freed);
      const auto cap = static_cast<uint64_t>(kHotOvershoot * static_cast<double>(max_bytes_));
      if (groups != 1 && left > cap) {
        // Past the overshoot the regions in use go too, but only back to the bound itself.
        const EnforceResult hot = residency_.enforce(tree, left, max_bytes_);
        if (hot.listed) {  // listed after the idle groups went
          listed = hot.listed;
          regions = hot.regions;
        }
      } else if (groups != 1 && left > max_bytes_) {
        std::lock_guard s(stats_mutex_);
        stats_.hot_overshoots++;  // everything left above the bound is in use: it stays
      }
    } catch (const std::exception& e) {  // the store refused a put: that region stays here
      std::lock_guard s(stats_mutex_);
      if (stats_.evict_failures++ == 0 || stats_.evict_failures % 1000 == 0)
        log_.warning(text("the region store refused an eviction (", stats_.evict_failures,
                          " so far; the map stays whole in memory, above --max-map-memory): ", e.what()));
      stats_.last_error = std::string("evict: ") + e.what();
    }
    if (listed) resident_regions_ = listed - regions;
    if (residency_.stats().evictions != before) count_residency_change();
  }
  publish_stats(tree);
  note_costs(0, ms_since(t0), walk_ms);
}

SweepSpill MapResidency::sweep_hooks(const RegionGrid& sweep) {
  // The residency's hooks, each under mutex_; restores and deletions count as map changes.
  SweepSpill s = residency_.sweep_hooks(sweep);
  auto locked = [this](auto f, bool change) {
    return [this, f = std::move(f), change](auto&&... args) {
      std::lock_guard lock(mutex_);
      const uint64_t before = residency_.stats().restores;
      if constexpr (std::is_same_v<decltype(f(args...)), void>) {
        f(args...);
        if (change || residency_.stats().restores != before) count_residency_change();
      } else {
        return f(args...);
      }
    };
  };
  s.bring_back = locked(std::move(s.bring_back), false);
  s.reshaped = locked(std::move(s.reshaped), false);
  s.spilled = locked(std::move(s.spilled), false);
  s.can_owe = locked(std::move(s.can_owe), false);
  s.stand_in = locked(std::move(s.stand_in), false);
  s.owe = locked(std::move(s.owe), false);
  s.drop = locked(std::move(s.drop), true);
  return s;
}

void MapResidency::adopt_loaded(RegionId id, std::span<const uint8_t> bytes) {
  std::lock_guard lock(mutex_);
  residency_.adopt_spilled(id, bytes);
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

MapResidency::SpilledRegions MapResidency::spilled_regions() const {
  std::lock_guard lock(mutex_);
  SpilledRegions out;
  for (RegionId id : residency_.spilled_ids())
    out.push_back(SpilledRegion{id, residency_.spilled_bytes(id), residency_.owed_steps(id)});
  return out;
}

void MapResidency::fill_copy(octomap::OcTree& copy, const RegionGrid& grid, const SpilledRegions& regions) {
  for (const SpilledRegion& r : regions) restore_region(copy, grid, r.id, r.bytes);
  // Every region is back: none is a stand-in when the owed steps settle the nodes above.
  for (const SpilledRegion& r : regions)
    if (!r.owed.empty()) apply_owed_steps(copy, grid, r.id, r.owed, nullptr);
}

MapResidencyStats MapResidency::stats() const {
  std::lock_guard lock(stats_mutex_);
  return stats_;
}

}  // namespace ort::daemon
