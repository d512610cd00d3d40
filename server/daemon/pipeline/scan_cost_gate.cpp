#include "daemon/pipeline/scan_cost_gate.h"

#include <algorithm>
#include <cmath>

namespace ort::daemon {
namespace {

// Full at first sight, then refilled at `rate` a second up to `burst`.
void refill(double& tokens, SteadyClock::time_point& refilled, SteadyClock::time_point now, double rate, double burst) {
  if (refilled == SteadyClock::time_point{}) {
    tokens = burst;
    refilled = now;
    return;
  }
  const double s = std::chrono::duration<double>(now - refilled).count();
  if (s <= 0) return;
  tokens = std::min(burst, tokens + s * rate);
  refilled = now;
}

std::string over(double tokens, double rate, const char* whose, const char* flag) {
  return std::string(whose) + " new nodes passed " + std::to_string(static_cast<int64_t>(rate)) + " a second (" + flag +
         "); " + std::to_string(static_cast<int64_t>(-tokens)) + " over the allowance";
}

}  // namespace

ScanCostGate::Track& ScanCostGate::track(size_t producer, SteadyClock::time_point now) {
  if (tracks_.size() <= producer) tracks_.resize(producer + 1);
  Track& t = tracks_[producer];
  if (t.nodes.refilled == SteadyClock::time_point{})
    refill(t.nodes.tokens, t.nodes.refilled, now, bounds_.max_new_nodes_per_s, bounds_.new_node_burst);
  return t;
}

Reject ScanCostGate::allowance_locked(Track& t, SteadyClock::time_point now, std::string& detail) {
  if (bounds_.max_new_nodes_per_s > 0) {
    refill(t.nodes.tokens, t.nodes.refilled, now, bounds_.max_new_nodes_per_s, bounds_.new_node_burst);
    if (t.nodes.tokens < 0) {
      detail = over(t.nodes.tokens, bounds_.max_new_nodes_per_s, "the robot's", "--max-new-nodes-per-s");
      return Reject::kNewNodeRate;
    }
  }
  if (bounds_.max_map_new_nodes_per_s > 0) {
    refill(map_.tokens, map_.refilled, now, bounds_.max_map_new_nodes_per_s, bounds_.map_new_node_burst);
    if (map_.tokens < 0) {
      detail = over(map_.tokens, bounds_.max_map_new_nodes_per_s, "all robots'", "--max-map-new-nodes-per-s");
      return Reject::kMapNewNodeRate;
    }
  }
  return Reject::kNone;
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

Reject ScanCostGate::admit_rays(double mean_ray_voxels, std::string& detail) const {
  if (bounds_.max_mean_ray_voxels <= 0 || mean_ray_voxels <= bounds_.max_mean_ray_voxels) return Reject::kNone;
  // As whole voxels; a mean of points 1e38 m out does not fit an integer (the fuzzer's find).
  auto whole = [](double v) { return std::to_string(static_cast<int64_t>(std::min(v, 1e18))); };
  detail = "the scan's rays are " + whole(mean_ray_voxels) + " voxels long on average, above " +
           whole(bounds_.max_mean_ray_voxels) + " (--max-mean-ray-voxels; a max range cuts them)";
  return Reject::kMeanRayTooLong;
}

Reject ScanCostGate::admit_stage_time(const StageCostPrediction& predicted, bool others_stream,
                                      std::string& detail) const {
  const double bound_ms = bounds_.max_scan_stage_s * 1e3;
  if (!(bound_ms > 0) || !others_stream || !predicted.learned || !(predicted.ms > bound_ms)) return Reject::kNone;
  detail = "the scan is predicted to take " + std::to_string(static_cast<int64_t>(std::min(predicted.ms, 1e15))) +
           " ms of the stages while other robots stream, above " + std::to_string(static_cast<int64_t>(bound_ms)) +
           " ms (--max-scan-time)";
  return Reject::kPredictedTooSlow;
}

Reject ScanCostGate::admit_voxels(uint64_t voxels, std::string& detail) const {
  if (bounds_.max_scan_voxels == 0 || voxels <= bounds_.max_scan_voxels) return Reject::kNone;
  detail = "the scan updates " + std::to_string(voxels) + " voxels, above " + std::to_string(bounds_.max_scan_voxels) +
           " (--max-scan-voxels)";
  return Reject::kTooManyVoxels;
}

void ScanCostGate::applied(size_t producer, int64_t new_nodes, SteadyClock::time_point now) {
  if (new_nodes <= 0) return;
  std::lock_guard lock(mutex_);
  if (bounds_.max_new_nodes_per_s > 0) {
    Track& t = track(producer, now);
    refill(t.nodes.tokens, t.nodes.refilled, now, bounds_.max_new_nodes_per_s, bounds_.new_node_burst);
    t.nodes.tokens -= static_cast<double>(new_nodes);
  }
  if (bounds_.max_map_new_nodes_per_s > 0) {
    refill(map_.tokens, map_.refilled, now, bounds_.max_map_new_nodes_per_s, bounds_.map_new_node_burst);
    map_.tokens -= static_cast<double>(new_nodes);
  }
}

}  // namespace ort::daemon
