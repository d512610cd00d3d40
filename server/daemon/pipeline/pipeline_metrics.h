// What the status reports about the pipeline: latency percentiles over a recent window,
// throughput over the last seconds, totals, and the overlap meter.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <vector>

#include "core/clock.h"
#include "core/ray_backend.h"
#include "daemon/pipeline/applied_timing.h"
#include "daemon/pipeline/latency_window.h"
#include "daemon/pipeline/overlap_meter.h"
#include "daemon/pipeline/slowest_scans.h"

namespace ort::daemon {

// p50 / p99 of one latency over the window.
struct Percentiles {
  double p50 = 0, p99 = 0;
};

struct MetricsSnapshot {
  double shoot_p50 = 0, shoot_p99 = 0, octree_p50 = 0, octree_p99 = 0, e2e_p50 = 0, e2e_p99 = 0;
  double scans_per_s = 0, points_per_s = 0;
  int64_t scans_applied = 0, points_applied = 0, overlapped_scans = 0;
  double shoot_total_ms = 0, octree_total_ms = 0;
  OverlapTotals overlap;
  Percentiles decode, queue_wait, handoff_wait;  // ScanWaits over the latency window
  // Stage 2's wait for the map lock (readers holding it: snapshot copies, saves, status
  // counts, queries): over the window, and the longest since start.
  Percentiles lock_wait;
  double lock_wait_max = 0;
  const char* lock_wait_max_holder = "";  // whom the longest wait waited for (map_lock_holders.h)
  StageTimes stage1_total;                // the engine's parts of stage 1, summed over every scan
  std::vector<SlowScan> slowest;          // the run's slowest scans end to end, slowest first
};

class PipelineMetrics {
 public:
  void record(const AppliedTiming& t);
  MetricsSnapshot snapshot();
  OverlapMeter& overlap() { return overlap_; }

 private:
  static constexpr double kRateWindowS = 10.0;
  std::mutex mutex_;
  LatencyWindow shoot_, octree_, e2e_, decode_, queue_wait_, handoff_wait_, lock_wait_;
  double lock_wait_max_ = 0;
  const char* lock_wait_max_holder_ = "";
  StageTimes stage1_total_;
  SlowestScans slowest_;
  std::deque<std::pair<SteadyClock::time_point, int64_t>> recent_;  // applied scans: time, points
  SteadyClock::time_point start_ = SteadyClock::now();
  int64_t scans_ = 0, points_ = 0, overlapped_ = 0;
  double shoot_total_ms_ = 0, octree_total_ms_ = 0;
  OverlapMeter overlap_;
};

}  // namespace ort::daemon
