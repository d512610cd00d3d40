#include "daemon/intake/shared_class_budget.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace ort::daemon {
namespace {

bool is_time(double ms) { return ms > 0 && std::isfinite(ms); }

// An eighth of the newest scan: follows the load within tens of scans, and one slow scan does
// not open the bound at once.
void follow(double& mean, double ms) { mean = mean > 0 ? 0.875 * mean + 0.125 * ms : ms; }

std::string whole(double v) { return std::to_string(static_cast<int64_t>(std::min(v, 1e15))); }

}  // namespace

void SharedClassBudget::robots_used(double ms) {
  if (is_time(ms)) robot_ms_unrefilled_ += ms;
}

void SharedClassBudget::shared_used(double ms) {
  if (is_time(ms)) tokens_ms_ -= ms;
}

void SharedClassBudget::scan_done(size_t producer, double ms, bool robot_with_history) {
  if (!is_time(ms)) return;
  if (robot_with_history) follow(robot_scan_mean_ms_, ms);
  if (producer >= own_scan_mean_ms_.size()) own_scan_mean_ms_.resize(producer + 1, 0);
  follow(own_scan_mean_ms_[producer], ms);
}

void SharedClassBudget::refill(SteadyClock::time_point now) {
  if (!started_) {  // full at first sight
    started_ = true;
    tokens_ms_ = bounds_.burst_ms;
    refilled_ = now;
    robot_ms_unrefilled_ = 0;
    return;
  }
  const double s = std::chrono::duration<double>(now - refilled_).count();
  if (s < 0) return;  // a clock read out of order refills nothing
  tokens_ms_ =
      std::min(bounds_.burst_ms, tokens_ms_ + s * bounds_.floor_ms_per_s + bounds_.robot_ratio * robot_ms_unrefilled_);
  robot_ms_unrefilled_ = 0;
  refilled_ = now;
}

bool SharedClassBudget::may_serve(SteadyClock::time_point now) {
  if (!bounds_.enabled) return true;
  refill(now);
  return tokens_ms_ >= 0;
}

double SharedClassBudget::scan_bound_ms(size_t producer) const {
  double scale = robot_scan_mean_ms_;
  if (!(scale > 0)) scale = producer < own_scan_mean_ms_.size() ? own_scan_mean_ms_[producer] : 0;
  if (!(scale > 0))  // the cheapest producer's: an attacker's applied far scans cannot open it
    for (const double m : own_scan_mean_ms_)
      if (m > 0 && (!(scale > 0) || m < scale)) scale = m;
  return std::max(bounds_.scan_floor_ms, bounds_.scan_ratio * scale);
}

std::string SharedClassBudget::refusal(size_t producer, const StageCostPrediction& predicted, double walk_voxels,
                                       double mean_ray_voxels, double longest_learned_ray_voxels) const {
  if (!bounds_.enabled) return {};
  const double unknown_above =
      std::max(bounds_.unknown_ray_floor_voxels, bounds_.unknown_ray_ratio * longest_learned_ray_voxels);
  if (!predicted.learned && mean_ray_voxels > unknown_above &&
      walk_voxels > bounds_.unknown_walk_floor_voxels)  // NaN is no ray length: the intake's bounds
    return "a robot id without history's rays are " + whole(mean_ray_voxels) + " voxels long on average, above " +
           whole(unknown_above) + ", " + whole(walk_voxels) + " voxels in all" +
           " (--shared-unknown-ray-floor or --shared-unknown-ray-ratio of the longest shape applied, --shared-unknown-walk-floor): its cost is "
           "not known while others stream (a voxel in unknown space costs far more than one in mapped space)";
  if (const double bound = scan_bound_ms(producer); predicted.learned && predicted.ms > bound)
    return "a robot id without history's scan is predicted to take " + whole(predicted.ms) +
           " ms of the stages while others stream, above " + whole(bound) +
           " ms (--shared-scan-floor, or --shared-scan-ratio of the robots' mean scan)";
  return {};
}

}  // namespace ort::daemon
