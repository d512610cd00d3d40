// The long-lived map's upkeep (issue 25): decay and clearing by distance, applied on the
// daemon's own steady clock (never the scans' utimes, which a peer controls), region by
// region in slices of bounded work, each slice under the map lock and applied as a map step
// (counted, and replayed on the read replica: daemon/map/sweep_slices.h); scans and queries
// run between slices.
//
// Decay: a step every `decay_step_s`; a sweep applies the steps due when it starts at once
// (factor 2^(-n * step / half-life) for n steps: octree/decay.h gives the exact rule).
// Clearing: every `clear_period_s`, everything wholly farther than `clear_radius_m` from
// every robot whose scan was applied within the last `clear_recent_s` seconds is deleted
// (octree/distance_clearing.h); with no such robot nothing is cleared.
//
// Mirrors (deltas) are told once a sweep ends: its changes are not a voxel list, so they
// resync from a snapshot then.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>

#include "core/clock.h"
#include "core/log.h"
#include "core/threads/periodic_thread.h"
#include "daemon/map/map_identity.h"
#include "daemon/map/map_state.h"
#include "octree/region.h"

namespace ort::daemon {

struct UpkeepConfig {
  double decay_half_life_s = 0;  // 0: no decay
  double decay_step_s = 0;       // 0: half-life / 16
  float decay_delete_below = 0.1f;
  double clear_radius_m = 0;  // 0: no clearing by distance
  double clear_recent_s = 0;  // robots seen within this long count; 0 with a radius: refused
  double clear_period_s = 5;
  unsigned region_depth = 10;
  uint64_t slice_nodes = 65536;  // nodes visited a slice (under the map lock)
  // Test mode: no thread, no clock; steps are taken by MapUpkeep::decay_steps().
  bool manual = false;

  bool decay_on() const { return decay_half_life_s > 0; }
  bool clearing_on() const { return clear_radius_m > 0; }
};

// Throws std::invalid_argument naming the flag when a field is out of range.
void validate_upkeep(const UpkeepConfig& c);

struct UpkeepStats {
  uint64_t decay_steps = 0, decay_sweeps = 0, clear_sweeps = 0, slices = 0;
  uint64_t nodes_deleted_by_decay = 0, nodes_deleted_by_clearing = 0;
  double max_slice_ms = 0;
};

class MapUpkeep {
 public:
  MapUpkeep(MapState& map, const UpkeepConfig& cfg, Log log);
  ~MapUpkeep();
  void start();  // the upkeep thread (not in manual mode, nor when nothing is on)
  void stop();   // joins it; a sweep under way ends at its current slice
  // Test mode: `n` decay steps now, as one sweep in slices (each slice under the lock).
  void decay_steps(uint64_t n);
  // Test mode: one clearing pass now, with the robots seen within clear_recent_s.
  void clear_now();
  UpkeepStats stats() const;

 private:
  void run_due_sweeps();  // the periodic task: the decay steps and the clearing pass now due
  void run_decay_sweep(uint64_t steps);
  void run_clear_sweep();
  // Runs the sweep `make` makes (on each tree at its first slice), slice by slice.
  template <class Sweep>
  void run_sweep(std::function<std::unique_ptr<Sweep>(const octomap::OcTree&)> make, uint64_t& deleted_counter);
  // The one place a slice changes the map: a map step (map_identity.h), counted and replayed
  // on the read replica. Caller holds the map lock exclusively.
  void apply_slice(const MapStep& slice);

  MapState& map_;
  UpkeepConfig cfg_;
  Log log_;
  RegionGrid grid_;
  SteadyClock::time_point start_, next_clear_;
  uint64_t steps_started_ = 0;
  mutable std::mutex stats_mutex_;
  UpkeepStats stats_;
  PeriodicThread periodic_;  // last: stopped before the members its task uses go
};

}  // namespace ort::daemon
