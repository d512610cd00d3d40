#include "daemon/map/map_upkeep.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "daemon/map/map_identity.h"
#include "daemon/map/map_residency.h"
#include "daemon/map/sweep_slices.h"
#include "octree/decay.h"
#include "octree/distance_clearing.h"

namespace ort::daemon {

void validate_upkeep(const UpkeepConfig& c) {
  auto seconds = [](double v, const char* flag, bool zero_ok) {
    if (!std::isfinite(v) || v < 0 || (!zero_ok && v == 0) || v > 1e9)
      throw std::invalid_argument(std::string(flag) + " must be a number of seconds in " +
                                  (zero_ok ? "[0, 1e9]" : "(0, 1e9]"));
  };
  seconds(c.decay_half_life_s, "--decay-half-life", true);
  seconds(c.decay_step_s, "--decay-step", true);
  if (!std::isfinite(c.decay_delete_below) || c.decay_delete_below < 0 || c.decay_delete_below > 10)
    throw std::invalid_argument("--decay-delete-below must be a log-odds in [0, 10]");
  if (!std::isfinite(c.clear_radius_m) || c.clear_radius_m < 0 || c.clear_radius_m > 1e6)
    throw std::invalid_argument("--clear-radius must be a number of metres in [0, 1e6]");
  seconds(c.clear_recent_s, "--clear-recent", true);
  seconds(c.clear_period_s, "--clear-period", false);
  if (c.clearing_on() && c.clear_recent_s == 0)
    throw std::invalid_argument("--clear-radius needs --clear-recent (how lately a robot must have sent a scan)");
  if (c.region_depth < 1 || c.region_depth > 16) throw std::invalid_argument("--region-depth must be in 1..16");
  if (c.slice_nodes == 0) throw std::invalid_argument("the upkeep's slice must visit at least one node");
}

MapUpkeep::MapUpkeep(MapState& map, const UpkeepConfig& cfg, Log log)
    : map_(map), cfg_(cfg), log_(std::move(log)), grid_(region_grid(cfg.region_depth)), start_(SteadyClock::now()) {
  validate_upkeep(cfg_);
  if (cfg_.decay_on() && cfg_.decay_step_s == 0) cfg_.decay_step_s = cfg_.decay_half_life_s / 16;
}

MapUpkeep::~MapUpkeep() { stop(); }

void MapUpkeep::start() {
  if (cfg_.manual || (!cfg_.decay_on() && !cfg_.clearing_on()) || periodic_.running()) return;
  start_ = SteadyClock::now();
  next_clear_ =
      start_ + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(cfg_.clear_period_s));
  PeriodicOptions o;
  o.run_first = true;
  // Looks every 50 ms whether a sweep is due (sweeps are rare; the look is two comparisons).
  periodic_.start(
      0.05, [this] { run_due_sweeps(); }, o);
}

void MapUpkeep::stop() { periodic_.stop(); }

UpkeepStats MapUpkeep::stats() const {
  std::lock_guard lock(stats_mutex_);
  return stats_;
}

void MapUpkeep::apply_slice(const MapStep& slice) { apply_map_step(map_, slice); }

template <class Sweep>
void MapUpkeep::run_sweep(std::function<std::unique_ptr<Sweep>(const octomap::OcTree&)> make,
                          uint64_t& deleted_counter) {
  // With a memory bound, spilled regions stay in the store, owing the sweep's step, and the
  // bound holds after every slice (daemon/map/map_residency.h).
  const octomap::OcTree* record = map_.tree.get();
  auto make_here = [residency = map_.residency, record, grid = grid_,
                    make = std::move(make)](const octomap::OcTree& t) {
    std::unique_ptr<Sweep> s = make(t);
    if (residency && &t == record) s->regions().set_spill(residency->sweep_hooks(grid));
    return s;
  };
  const auto [slices, slice] = SweepSlices<Sweep>::steps(std::move(make_here), cfg_.slice_nodes);
  bool done = false;
  uint64_t deleted_before = 0, deleted = 0;
  while (!done) {
    const auto t0 = SteadyClock::now();
    {
      std::unique_lock lock(map_.mutex);
      const MapHoldNote note(map_.holders, "upkeep slice");
      try {
        apply_slice(slice);
        done = slices->on(*map_.tree)->done();
      } catch (const std::exception& e) {  // the region store could not give a region back
        log_.error(
            text("a sweep stopped before its end (the regions it reached are swept, the rest wait for "
                 "the next): ",
                 e.what()));
        // Only with a memory bound, where the server runs without a replica: what the slice
        // did is counted as a change, and the sweep ends.
        count_map_change(map_);
        done = true;
      }
      if (map_.residency) map_.residency->enforce(*map_.tree);
      if (const Sweep* sweep = slices->on(*map_.tree)) deleted = sweep->nodes_deleted();
      // Deltas cannot carry the sweep: mirrors resync once it is whole.
      if (done && map_.observer) map_.observer->replaced(*map_.tree, map_.version, map_.epoch);
    }
    map_.changed.notify_all();
    const double ms = ms_since(t0);
    {
      std::lock_guard lock(stats_mutex_);
      stats_.slices++;
      stats_.max_slice_ms = std::max(stats_.max_slice_ms, ms);
      deleted_counter += deleted - deleted_before;
    }
    deleted_before = deleted;
    // Scans and queries get the lock between slices; a stop ends the sweep here.
    if (!done && !cfg_.manual && !periodic_.pause(std::chrono::milliseconds(1))) return;
  }
}

void MapUpkeep::run_decay_sweep(uint64_t steps) {
  const DecayRule rule{decay_factor(double(steps) * cfg_.decay_step_s, cfg_.decay_half_life_s),
                       cfg_.decay_delete_below};
  std::function<std::unique_ptr<DecaySweep>(const octomap::OcTree&)> make =
      [grid = grid_, rule](const octomap::OcTree& t) { return std::make_unique<DecaySweep>(t, grid, rule); };
  run_sweep(std::move(make), stats_.nodes_deleted_by_decay);
  std::lock_guard lock(stats_mutex_);
  stats_.decay_steps += steps;
  stats_.decay_sweeps++;
}

void MapUpkeep::run_clear_sweep() {
  std::vector<octomap::point3d> centres;
  {
    std::shared_lock lock(map_.mutex);
    const auto now = SteadyClock::now();
    for (const auto& [robot, seen] : map_.robots_seen)
      if (std::chrono::duration<double>(now - seen.applied).count() <= cfg_.clear_recent_s)
        centres.push_back(seen.origin);
  }
  if (centres.empty()) return;  // no robot seen lately: nothing is cleared
  std::function<std::unique_ptr<DistanceClearingSweep>(const octomap::OcTree&)> make =
      [grid = grid_, centres = std::move(centres), radius = cfg_.clear_radius_m](const octomap::OcTree& t) {
        return std::make_unique<DistanceClearingSweep>(t, grid, centres, radius);
      };
  run_sweep(std::move(make), stats_.nodes_deleted_by_clearing);
  std::lock_guard lock(stats_mutex_);
  stats_.clear_sweeps++;
}

void MapUpkeep::decay_steps(uint64_t n) {
  if (n == 0 || !cfg_.decay_on()) return;
  run_decay_sweep(n);
}

void MapUpkeep::clear_now() {
  if (cfg_.clearing_on()) run_clear_sweep();
}

void MapUpkeep::run_due_sweeps() {
  const auto now = SteadyClock::now();
  if (cfg_.decay_on()) {
    const auto due = static_cast<uint64_t>(std::chrono::duration<double>(now - start_).count() / cfg_.decay_step_s);
    if (due > steps_started_) {
      const uint64_t n = due - steps_started_;
      steps_started_ = due;
      run_decay_sweep(n);
    }
  }
  if (cfg_.clearing_on() && SteadyClock::now() >= next_clear_) {
    run_clear_sweep();
    next_clear_ = SteadyClock::now() +
                  std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(cfg_.clear_period_s));
  }
}

}  // namespace ort::daemon
