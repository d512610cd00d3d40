// The memory bound's working set (issue 25): the regions "in use", which eviction below the
// bound leaves alone. A region is in use for T seconds of the daemon's monotonic clock after
// its last touch.
//
// Why time and not a count of changes: the robots come back to the regions they map after
// some time, whatever the other robots do meanwhile. With a window of the last N changes,
// more robots (or faster ones) shrink it below that time, and eviction takes the regions the
// next scans restore (docs/BENCHMARKS.md "The memory bound": the soak's evictions and restores).
//
// T is fixed (a caller's choice), or by default follows the scan rate: kRateFactor times the
// longest mean interval between two scans of one source (a robot), an exponentially weighted
// mean, clamped to [kMinSeconds, kMaxSeconds]; kFirstSeconds until some source has sent a
// second scan. An interval longer than kPauseSeconds is a pause (a robot parked, the daemon
// idle), not a rate: it is not counted. At most kMaxSources sources are kept (robot ids come
// from the bus, so their number is not ours to bound): past that the one heard from longest
// ago goes. T is recomputed at each scan.
//
// The clock is injected, so tests step it. Not thread-safe: its owner serializes the calls.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <unordered_map>

#include "core/clock.h"
#include "octree/region.h"

namespace ort {

class WorkingSetWindow {
 public:
  using TimePoint = SteadyClock::time_point;
  using Clock = std::function<TimePoint()>;

  static constexpr double kRateFactor = 50;
  static constexpr double kMinSeconds = 1;
  static constexpr double kMaxSeconds = 120;
  static constexpr double kFirstSeconds = 5;
  static constexpr double kPauseSeconds = 120;
  static constexpr double kMeanWeight = 0.1;  // of the newest interval in the mean
  static constexpr size_t kMaxSources = 1024;

  // `fixed_seconds` > 0: T is that; 0: T follows the scan rate. `clock` empty: the steady clock.
  explicit WorkingSetWindow(double fixed_seconds = 0, Clock clock = {});

  TimePoint now() const { return clock_ ? clock_() : SteadyClock::now(); }

  // A scan from `source` arrived (now): its interval feeds the rate, and T is recomputed.
  void scan(std::string_view source);
  // Region `id` was touched at `at` (a caller touching many reads the clock once: now()).
  void touch(RegionId id, TimePoint at) { touched_[id] = at; }
  // Region `id` is no longer in the map.
  void forget(RegionId id) { touched_.erase(id); }

  // T, in seconds.
  double seconds() const { return seconds_; }
  // Regions last touched at or before this moment are idle, later ones in use (now - T).
  // An eviction pass reads it once and compares each region's last_touch() with it.
  TimePoint idle_before() const;
  // The region's last touch; TimePoint::min() when never touched (a map loaded from its
  // file: idle).
  TimePoint last_touch(RegionId id) const;
  bool in_use(RegionId id) const { return last_touch(id) > idle_before(); }

  size_t sources() const { return sources_.size(); }

 private:
  struct Source {
    TimePoint last;
    double mean_s = 0;
    bool has_mean = false;  // false: one scan only (or only pauses since)
  };
  void drop_oldest_source();
  void recompute();

  double fixed_s_;
  Clock clock_;
  double seconds_;
  std::unordered_map<std::string, Source> sources_;
  std::unordered_map<RegionId, TimePoint> touched_;
};

}  // namespace ort
