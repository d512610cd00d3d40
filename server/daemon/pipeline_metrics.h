// What the status reports about the pipeline: latency percentiles over a recent window,
// throughput over the last seconds, totals, and the overlap meter.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>

#include "core/ray_backend.h"
#include "daemon/latency_window.h"
#include "daemon/overlap_meter.h"

namespace ort::daemon {

// Where one scan's end-to-end time went besides the two stages: receipt -> decoded and
// queued (LCM thread) -> taken by stage 1 -> stage 1 done -> taken by stage 2.
struct ScanWaits {
  double decode_ms = 0;   // the LCM thread decoding and checking the message
  double queue_ms = 0;    // in the scan queue, behind scans that came before it
  double handoff_ms = 0;  // shot, waiting for stage 2 to finish the scan before it
};

struct AppliedTiming {
  double shoot_ms = 0;       // stage 1 wall time: to map frame + MapEngine::shoot
  double octree_ms = 0;      // stage 2 wall time: MapEngine::apply (map lock held)
  double end_to_end_ms = 0;  // receipt by the LCM thread -> applied
  int64_t points = 0;
  bool overlapped = false;   // its octree update overlapped a shoot of another scan
  ScanWaits waits;
  StageTimes stage1;         // the engine's parts of stage 1 (prepare, upload, shoot, compact)
};

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
  StageTimes stage1_total;                       // the engine's parts of stage 1, summed over every scan
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
  LatencyWindow shoot_, octree_, e2e_, decode_, queue_wait_, handoff_wait_;
  StageTimes stage1_total_;
  std::deque<std::pair<Clock::time_point, int64_t>> recent_;  // applied scans: time, points
  Clock::time_point start_ = Clock::now();
  int64_t scans_ = 0, points_ = 0, overlapped_ = 0;
  double shoot_total_ms_ = 0, octree_total_ms_ = 0;
  OverlapMeter overlap_;
};

}  // namespace ort::daemon
