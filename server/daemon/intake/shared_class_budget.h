// What the shared class (every producer without history, intake/scan_queue.h) may take of the
// stages (docs/RELIABILITY.md, "Share of the stages").
//
// Fair queuing alone does not protect a robot's latency: a robot at 5 Hz whose scans take 5 ms
// is idle most of the time, so a work-conserving scheduler hands the idle stages to whoever
// waits, and one far scan of a fresh id then holds stage 1 for ~650 ms (H200, far400 hostile
// mix: robot p99 5.63 s against 10.1 ms quiet). A scan is applied whole, so what bounds a
// robot's wait is what one scan ahead of it may cost. Two bounds:
//  - per scan, while another producer streams (alone, a scan delays no one): a shared-class
//    scan is refused before it is shot ("predicted too slow") when it is predicted, from
//    scans of its shape that ran, to take more than max(scan_floor_ms, scan_ratio times the
//    mean applied scan of the robots with history; before any has history, of the producer's
//    own applied scans, or else of the cheapest producer's: every producer's mean would be
//    the far scans', and one applied alone made the bound seconds); and when its cost is not
//    known: not learned, its rays longer on average than max(unknown_ray_floor_voxels,
//    unknown_ray_ratio times the longest shape ever applied), and its walk over
//    unknown_walk_floor_voxels.
//    Such rays walk into space no applied scan reached, where every voxel is a new node and
//    costs orders of magnitude more than one of a robot's rays through mapped space, so a
//    borrowed rate would let it through (the first far scan did, on every run before);
//  - per second, while a robot with history streams: a budget of stage time refilled at
//    floor_ms_per_s plus robot_ratio times what the robots used, up to burst_ms; the shared
//    class is served only while it is not below zero (its scans wait meanwhile; one that
//    waits past the latency bound is dropped as "over its share"), and what its scans took is
//    taken from it. Not while no robot has history: then every producer is in the shared class
//    and the budget would throttle them all.
// Not thread-safe: the queue calls it under its mutex. Times are passed in (tests inject them).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/clock.h"
#include "daemon/intake/stage_cost_model.h"

namespace ort::daemon {

struct SharedClassBounds {
  bool enabled = true;
  double floor_ms_per_s = 50;  // the shared class's stage time per second, at least
  double robot_ratio = 1.0;    // plus as much as the robots used (a new robot's first scans fit)
  double burst_ms = 500;       // the most it may save up
  double scan_floor_ms = 20;   // one scan's predicted stage time, at least allowed
  double scan_ratio = 4;       // against the mean applied scan's stage time
  // Rays of unknown cost: longer on average than this many voxels (51 m at 0.1 m; the real
  // scan sets here average 27-170) and than unknown_ray_ratio times the longest shape applied.
  double unknown_ray_floor_voxels = 512;
  double unknown_ray_ratio = 4;
  // ... and walking more voxels in all than this (a few long-range points are cheap whatever
  // their space; 100 points 400 m out at 0.1 m walk 400 000).
  double unknown_walk_floor_voxels = 100'000;

  static SharedClassBounds off() {
    SharedClassBounds b;
    b.enabled = false;
    return b;
  }
};

class SharedClassBudget {
 public:
  explicit SharedClassBudget(SharedClassBounds b = {}) : bounds_(b) {}

  // Stage time measured: of a robot with history's scan, or of the shared class's.
  void robots_used(double ms);
  void shared_used(double ms);
  // The producer's scan left the stages applied, having taken `ms` of them (the scale of the
  // per-scan bound).
  void scan_done(size_t producer, double ms, bool robot_with_history);
  // The shared class may be served now (its budget is not below zero). Refills to `now`.
  bool may_serve(SteadyClock::time_point now);
  // The most one shared-class scan of the producer may be predicted to take while others
  // stream [ms].
  double scan_bound_ms(size_t producer) const;
  // Empty, or why a shared-class scan is refused while others stream: its prediction, its
  // rays' mean length [voxels] and the longest learned shape's (StageCostModel).
  std::string refusal(size_t producer, const StageCostPrediction& predicted, double walk_voxels, double mean_ray_voxels,
                      double longest_learned_ray_voxels) const;

  double tokens_ms() const { return tokens_ms_; }
  const SharedClassBounds& bounds() const { return bounds_; }

 private:
  void refill(SteadyClock::time_point now);

  SharedClassBounds bounds_;
  double tokens_ms_ = 0;
  bool started_ = false;
  SteadyClock::time_point refilled_;
  double robot_ms_unrefilled_ = 0;        // robots' stage time since the last refill
  double robot_scan_mean_ms_ = 0;         // robots with history; 0: none applied yet
  std::vector<double> own_scan_mean_ms_;  // by producer; 0: none applied
};

}  // namespace ort::daemon
