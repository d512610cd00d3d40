#include "daemon/pipeline/scan_cost_gate.h"

#include <algorithm>
#include <cmath>

namespace ort::daemon {

ScanCostGate::Track& ScanCostGate::track(size_t producer, SteadyClock::time_point now) {
  if (tracks_.size() <= producer) tracks_.resize(producer + 1);
  Track& t = tracks_[producer];
  if (t.refilled == SteadyClock::time_point{}) {
    t.tokens = bounds_.new_node_burst;
    t.refilled = now;
  }
  return t;
}

void ScanCostGate::refill(Track& t, SteadyClock::time_point now) const {
  const double s = std::chrono::duration<double>(now - t.refilled).count();
  if (s <= 0) return;
  t.tokens = std::min(bounds_.new_node_burst, t.tokens + s * bounds_.max_new_nodes_per_s);
  t.refilled = now;
}

Reject ScanCostGate::allowance_locked(Track& t, SteadyClock::time_point now, std::string& detail) const {
  if (bounds_.max_new_nodes_per_s <= 0) return Reject::kNone;
  refill(t, now);
  if (t.tokens >= 0) return Reject::kNone;
  detail = "the robot's new nodes passed " + std::to_string(static_cast<int64_t>(bounds_.max_new_nodes_per_s)) +
           " a second (--max-new-nodes-per-s); " + std::to_string(static_cast<int64_t>(-t.tokens)) +
           " over its allowance";
  return Reject::kNewNodeRate;
}

Reject ScanCostGate::admit_allowance(size_t producer, SteadyClock::time_point now, std::string& detail) {
  std::lock_guard lock(mutex_);
  return allowance_locked(track(producer, now), now, detail);
}

Reject ScanCostGate::admit_origin(size_t producer, const octomap::point3d& origin, SteadyClock::time_point now,
                                  std::string& detail) {
  std::lock_guard lock(mutex_);
  Track& t = track(producer, now);
  if (const Reject r = allowance_locked(t, now, detail); r != Reject::kNone) return r;
  if (bounds_.max_origin_jump_m > 0 && t.seen) {
    const double s = std::max(0.0, std::chrono::duration<double>(now - t.at).count());
    const double allowed = bounds_.max_origin_jump_m + bounds_.max_speed_mps * s;
    const double jump = (origin - t.origin).norm();
    if (!(jump <= allowed)) {
      detail = "origin " + std::to_string(jump) + " m from the robot's last scan " + std::to_string(s) +
               " s ago; at most " + std::to_string(allowed) + " m (--max-origin-jump, --max-robot-speed)";
      return Reject::kOriginJump;
    }
  }
  t.seen = true;
  t.origin = origin;
  t.at = now;
  return Reject::kNone;
}

Reject ScanCostGate::admit_voxels(uint64_t voxels, std::string& detail) const {
  if (bounds_.max_scan_voxels == 0 || voxels <= bounds_.max_scan_voxels) return Reject::kNone;
  detail = "the scan updates " + std::to_string(voxels) + " voxels, above " + std::to_string(bounds_.max_scan_voxels) +
           " (--max-scan-voxels)";
  return Reject::kTooManyVoxels;
}

void ScanCostGate::applied(size_t producer, int64_t new_nodes, SteadyClock::time_point now) {
  if (bounds_.max_new_nodes_per_s <= 0 || new_nodes <= 0) return;
  std::lock_guard lock(mutex_);
  Track& t = track(producer, now);
  refill(t, now);
  t.tokens -= static_cast<double>(new_nodes);
}

}  // namespace ort::daemon
