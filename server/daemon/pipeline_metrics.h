// What the status reports about the pipeline: latency percentiles over a recent window,
// throughput over the last seconds, totals, and the overlap meter.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>

#include "daemon/latency_window.h"
#include "daemon/overlap_meter.h"

namespace ort::daemon {

struct AppliedTiming {
  double shoot_ms = 0;       // stage 1 wall time: to map frame + MapEngine::shoot
  double octree_ms = 0;      // stage 2 wall time: MapEngine::apply (map lock held)
  double end_to_end_ms = 0;  // receipt by the LCM thread -> applied
  int64_t points = 0;
  bool overlapped = false;   // its octree update overlapped a shoot of another scan
};

struct MetricsSnapshot {
  double shoot_p50 = 0, shoot_p99 = 0, octree_p50 = 0, octree_p99 = 0, e2e_p50 = 0, e2e_p99 = 0;
  double scans_per_s = 0, points_per_s = 0;
  int64_t scans_applied = 0, points_applied = 0, overlapped_scans = 0;
  double shoot_total_ms = 0, octree_total_ms = 0;
  OverlapTotals overlap;
};

class PipelineMetrics {
 public:
  using Clock = std::chrono::steady_clock;
  void record(const AppliedTiming& t);
  MetricsSnapshot snapshot();
  OverlapMeter& overlap() { return overlap_; }

 private:
  static constexpr double kRateWindowS = 10.0;
  std::mutex mutex_;
  LatencyWindow shoot_, octree_, e2e_;
  std::deque<std::pair<Clock::time_point, int64_t>> recent_;  // applied scans: time, points
  Clock::time_point start_ = Clock::now();
  int64_t scans_ = 0, points_ = 0, overlapped_ = 0;
  double shoot_total_ms_ = 0, octree_total_ms_ = 0;
  OverlapMeter overlap_;
};

}  // namespace ort::daemon
