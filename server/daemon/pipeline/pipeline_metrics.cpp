#include "daemon/pipeline/pipeline_metrics.h"

#include <algorithm>

#include "core/clock.h"

namespace ort::daemon {

void PipelineMetrics::record(const AppliedTiming& t) {
  const auto now = SteadyClock::now();
  std::lock_guard lock(mutex_);
  shoot_.add(t.shoot_ms);
  octree_.add(t.octree_ms);
  e2e_.add(t.end_to_end_ms);
  decode_.add(t.waits.decode_ms);
  queue_wait_.add(t.waits.queue_ms);
  handoff_wait_.add(t.waits.handoff_ms);
  lock_wait_.add(t.stage2.lock_wait_ms);
  if (t.stage2.lock_wait_ms > lock_wait_max_) {
    lock_wait_max_ = t.stage2.lock_wait_ms;
    lock_wait_max_holder_ = t.stage2.lock_holder;
  }
  stage1_total_.add(t.stage1);
  slowest_.add(t);
  scans_++;
  points_ += t.points;
  overlapped_ += t.overlapped ? 1 : 0;
  shoot_total_ms_ += t.shoot_ms;
  octree_total_ms_ += t.octree_ms;
  recent_.emplace_back(now, t.points);
  while (!recent_.empty() && std::chrono::duration<double>(now - recent_.front().first).count() > kRateWindowS)
    recent_.pop_front();
}

MetricsSnapshot PipelineMetrics::snapshot() {
  MetricsSnapshot s;
  s.overlap = overlap_.totals();
  const auto now = SteadyClock::now();
  std::lock_guard lock(mutex_);
  s.shoot_p50 = shoot_.percentile(0.5);
  s.shoot_p99 = shoot_.percentile(0.99);
  s.octree_p50 = octree_.percentile(0.5);
  s.octree_p99 = octree_.percentile(0.99);
  s.e2e_p50 = e2e_.percentile(0.5);
  s.e2e_p99 = e2e_.percentile(0.99);
  auto both = [](const LatencyWindow& w) { return Percentiles{w.percentile(0.5), w.percentile(0.99)}; };
  s.decode = both(decode_);
  s.queue_wait = both(queue_wait_);
  s.handoff_wait = both(handoff_wait_);
  s.lock_wait = both(lock_wait_);
  s.lock_wait_max = lock_wait_max_;
  s.lock_wait_max_holder = lock_wait_max_holder_;
  s.stage1_total = stage1_total_;
  s.slowest = slowest_.slowest();
  while (!recent_.empty() && std::chrono::duration<double>(now - recent_.front().first).count() > kRateWindowS)
    recent_.pop_front();
  const double window = std::min(kRateWindowS, std::chrono::duration<double>(now - start_).count());
  if (window > 0) {
    int64_t pts = 0;
    for (const auto& r : recent_) pts += r.second;
    s.scans_per_s = static_cast<double>(recent_.size()) / window;
    s.points_per_s = static_cast<double>(pts) / window;
  }
  s.scans_applied = scans_;
  s.points_applied = points_;
  s.overlapped_scans = overlapped_;
  s.shoot_total_ms = shoot_total_ms_;
  s.octree_total_ms = octree_total_ms_;
  return s;
}

}  // namespace ort::daemon
