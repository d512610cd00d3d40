// The two-stage pipeline. Stage 1 (GPU) takes scans from the queue in arrival order, puts
// them in the map frame and shoots their rays (MapEngine::shoot); stage 2 (CPU) applies each
// shot scan to the octree under the map lock (MapEngine::apply) and records it in the
// applied order. A hand-off of one slot between them lets stage 1 shoot scan k+1 while
// stage 2 applies scan k. Without pipelining, one thread runs both stages per scan.
#pragma once

#include <atomic>
#include <iosfwd>
#include <thread>

#include "core/clock.h"
#include "core/log.h"
#include "daemon/intake/producer_registry.h"
#include "daemon/intake/scan_queue.h"
#include "daemon/map/map_edit_item.h"
#include "daemon/map/map_state.h"
#include "daemon/pipeline/bounded_handoff.h"
#include "daemon/pipeline/filtered_shoot.h"
#include "daemon/pipeline/pipeline_metrics.h"
#include "daemon/pipeline/scan_cost_gate.h"
#include "daemon/pipeline/shard_filter.h"
#include "engine/map_engine.h"

namespace ort::daemon {

struct ShotJob {
  size_t producer = 0;
  size_t share_class = 0;  // whose share of the stages its time is charged to (intake/scan_queue.h)
  uint64_t arrival = 0;    // its number in the queue (what its time is charged as)
  std::string robot_id;
  int64_t seq = 0, utime = 0, points = 0;
  SteadyClock::time_point received;
  SteadyClock::time_point shot_at;  // when stage 1 finished it
  ScanWaits waits;                  // decode and queue wait so far; stage 2 adds its hand-off wait
  double shoot_ms = 0;
  octomap::point3d origin;  // the sensor's, in the map frame
  ShotScan shot;
  FilterCounts filtered;              // points the server's filters removed before preparation
  std::shared_ptr<MapEditItem> edit;  // set: apply this edit instead of a scan
};

class ScanPipeline {
 public:
  // `max_queue_age` > 0: overload shedding. A scan that waited longer than this in the
  // queue is dropped when it comes out (counted: "over latency bound"), so end-to-end
  // latency stays near the bound instead of growing without limit.
  // `log` is the daemon's log stream (engine errors, step-guard warnings).
  ScanPipeline(MapEngine& engine, MapState& map, ScanQueue& queue, ProducerRegistry& producers,
               PipelineMetrics& metrics, Log log, bool pipelined,
               std::chrono::duration<double> max_queue_age = std::chrono::duration<double>::zero(),
               const PointFilters& filters = {});
  ~ScanPipeline();
  // What one producer's scans may cost (pipeline/scan_cost_gate.h); call before start().
  void set_cost_bounds(const ScanCostBounds& b) { gate_ = ScanCostGate(b); }
  // A shard's regions (pipeline/shard_filter.h): stage 1 keeps only their voxels; call before start().
  // The engine then leaves out the rays that meet none of its regions (MapEngine::set_ray_clip).
  void set_shard(const ShardFilter& f) {
    shard_ = f;
    if (shard_.active()) engine_.set_ray_clip([this](const KeyBox& box) { return shard_.may_hold(box); });
  }
  void start();
  // Call after queue.close(): returns once every queued scan was applied or rejected.
  void join();
  size_t shot_depth() const { return handoff_.size(); }
  int64_t engine_errors() const { return engine_errors_; }
  int64_t shed() const { return shed_; }
  // How long the stage busiest on one scan has been on it (zero when both are idle): a
  // stage stuck on one scan shows here.
  SteadyClock::duration longest_busy(SteadyClock::time_point now = SteadyClock::now()) const;

 private:
  // Stage 1 on one scan; false when it ended as a rejection.
  bool shoot(QueuedScan& item, ShotJob& job);
  // Stage 2 on one scan; true when it was applied (whole: a scan is never half-applied).
  bool apply(ShotJob& job);
  void apply_edit(MapEditItem& edit);
  void reject(size_t producer, Reject why, const char* what);
  // A scan refused by the cost gate: counted, the first few logged with the detail.
  void refuse_cost(size_t producer, Reject why, const std::string& detail);
  void run_stage1();
  void run_stage2();
  void run_sequential();
  // True (and counted as dropped: over its share when other producers were served in its
  // turn, else over latency bound) when the scan waited longer than max_queue_age_.
  bool shed_if_stale(const QueuedScan& item);
  void set_busy(int stage, bool busy);

  MapEngine& engine_;
  MapState& map_;
  ScanQueue& queue_;
  ProducerRegistry& producers_;
  PipelineMetrics& metrics_;
  Log log_;
  bool pipelined_;
  BoundedHandoff<ShotJob> handoff_{1};
  ScanCostGate gate_{ScanCostBounds{}};
  ShardFilter shard_;
  int64_t cost_refusals_logged_ = 0;
  LeafChanges changes_;  // stage 2's: what the scan being applied changed, for map_.observer
  std::thread stage1_, stage2_;
  std::atomic<int64_t> engine_errors_{0}, shed_{0};
  int64_t overrun_warnings_ = 0;  // stage 1 only
  std::chrono::duration<double> max_queue_age_;
  PointFilters filters_;
  FilterScratch filter_scratch_;                    // stage 1 only
  std::atomic<int64_t> busy_since_ns_[2] = {0, 0};  // steady clock; 0: idle
};

}  // namespace ort::daemon
