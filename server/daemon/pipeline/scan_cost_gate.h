// What one producer's scans may cost the map over time (docs/RELIABILITY.md, "Bounded
// cost"): a scan is refused before it is shot or applied, never half-applied, when
//  - its origin is farther from where that robot's last scan was than it could have moved
//    (max_origin_jump_m plus max_speed_mps for every second since): one 100-point scan far
//    away adds millions of nodes, and origins that move do not stay within a range limit;
//  - it would update more voxels than max_scan_voxels (a campus LiDAR scan updates ~8 M);
//  - its rays are longer on average than max_mean_ray_voxels: a scan's cost is its rays'
//    walks, so a few points far out cost what a real scan's ten thousand do (100 points 1 km
//    out at 0.1 m add ~2-3 M nodes), from the first scan of a robot id without history on.
//    Decided from the message before any ray is shot;
//  - (a producer without history) it is predicted to take more of the stages than
//    max_scan_stage_s (its walk times what a voxel of its shape took in the scans applied
//    before: intake/stage_cost_model.h) while another producer streams (scans waiting, in the stages, or served within the queue's
//    kStreamingWindow): a scan is applied whole, so what the others wait for is its whole
//    time; alone it delays no one. Decided from a learned prediction only;
//  - the producer's new-node allowance is spent: each applied scan's new nodes are taken
//    from a bucket refilled at max_new_nodes_per_s up to new_node_burst, and while the
//    bucket is below zero the producer's scans are refused;
//  - the map's new-node allowance is spent: the same bucket for all producers together
//    (max_map_new_nodes_per_s, map_new_node_burst), so that many robot ids, each within its
//    own allowance, cannot grow the map without a bound either.
// Refusals are counted per producer with their reason (ProducerRegistry); the status shows
// them. Stage 1 asks (admit_origin, admit_voxels), stage 2 reports what it applied.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include <octomap/octomap_types.h>

#include "core/clock.h"
#include "daemon/intake/reject_reason.h"
#include "daemon/intake/shared_class_budget.h"
#include "daemon/intake/stage_cost_model.h"

namespace ort::daemon {

struct ScanCostBounds {
  double max_origin_jump_m = 100;         // <= 0: origins unchecked
  double max_speed_mps = 50;              // added to the jump for each second since the last scan
  uint64_t max_scan_voxels = 64'000'000;  // 0: no limit
  // Far above real scan sets' mean rays (docs/RELIABILITY.md, "Bounded cost"); 4096 is a
  // 410 m mean at 0.1 m. 0: no limit.
  double max_mean_ray_voxels = 4096;
  double max_new_nodes_per_s = 4'000'000;       // <= 0: no limit
  double new_node_burst = 32'000'000;           // a campus LiDAR scan's ~8 M new voxels fit
  double max_map_new_nodes_per_s = 16'000'000;  // all producers together; <= 0: no limit
  double map_new_node_burst = 128'000'000;
  // The map's utime follows its newest scan's, but never more than this ahead of the
  // daemon's clock (a scan stamped years ahead would pin it there).
  double max_future_s = 60;
  // The stages' time shared among producers (intake/scan_queue.h): a producer has a share of
  // its own once it has sent share_history_scans valid scans over share_history_s seconds;
  // before, it shares one with every other producer without history. false: one FIFO. A
  // robot streaming at 2 Hz or more has its own share after 5 s; an attacker's ids earn one
  // however long this is (the allow-list bounds those), so it is kept short.
  bool producer_share = true;
  int64_t share_history_scans = 10;
  double share_history_s = 5;
  // The shared class's share against 1 for each producer with history (intake/scan_queue.h).
  double shared_class_share = 0.25;
  // The most of the stages' time (both together) one scan of a producer without history may
  // be predicted to take while another producer streams; two fifths of the default latency
  // bound. 0: no limit.
  double max_scan_stage_s = 2.0;
  // While a robot with history streams, what the shared class may take of the stages per
  // second and per scan (intake/shared_class_budget.h).
  SharedClassBounds shared;
};

class ScanCostGate {
 public:
  explicit ScanCostGate(ScanCostBounds b) : bounds_(b) {}
  ScanCostGate& operator=(ScanCostGate&& o) noexcept {
    bounds_ = o.bounds_;
    tracks_ = std::move(o.tracks_);
    map_ = o.map_;
    return *this;
  }

  // kNone, or why the producer's scan with this origin is refused (kOriginJump: too far from
  // the robot's last scan; kNewNodeRate: its allowance is spent; kMapNewNodeRate: the map's
  // is). `detail` says by how much.
  Reject admit_origin(size_t producer, const octomap::point3d& origin, SteadyClock::time_point now,
                      std::string& detail);
  // kNone, or kNewNodeRate / kMapNewNodeRate when the producer's or the map's allowance is
  // spent (asked again by stage 2 right before it applies: stage 1 may have admitted the scan
  // while the one before was being applied).
  Reject admit_allowance(size_t producer, SteadyClock::time_point now, std::string& detail);
  // kNone, or kMeanRayTooLong when the scan's rays are longer on average (in voxels, cut at
  // its max range: intake/scan_to_map.h's ray_lengths) than the bound.
  Reject admit_rays(double mean_ray_voxels, std::string& detail) const;
  // kNone, or kPredictedTooSlow when the scan is predicted (learned, not guessed) to take more
  // of the stages than the bound while `others_stream`.
  Reject admit_stage_time(const StageCostPrediction& predicted, bool others_stream, std::string& detail) const;
  // kNone, or kTooManyVoxels when the shot scan updates more voxels than the bound.
  Reject admit_voxels(uint64_t voxels, std::string& detail) const;
  // Stage 2 applied the producer's scan: its new nodes are taken from its allowance and the map's.
  void applied(size_t producer, int64_t new_nodes, SteadyClock::time_point now);

  const ScanCostBounds& bounds() const { return bounds_; }
  int64_t max_future_us() const { return static_cast<int64_t>(bounds_.max_future_s * 1e6); }

 private:
  // New nodes allowed: refilled at `rate` a second up to `burst`; spent while below zero.
  struct Allowance {
    double tokens = 0;
    SteadyClock::time_point refilled;
  };
  struct Track {
    bool seen = false;
    octomap::point3d origin;
    SteadyClock::time_point at;
    Allowance nodes;
  };
  Track& track(size_t producer, SteadyClock::time_point now);  // under mutex_
  // Both allowances refilled to `now`; kNone, or which one is spent (and `detail`).
  Reject allowance_locked(Track& t, SteadyClock::time_point now, std::string& detail);

  ScanCostBounds bounds_;
  std::mutex mutex_;
  std::vector<Track> tracks_;  // by producer index
  Allowance map_;              // all producers'
};

}  // namespace ort::daemon
