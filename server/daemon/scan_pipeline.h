// The two-stage pipeline. Stage 1 (GPU) takes scans from the queue in arrival order, puts
// them in the map frame and shoots their rays (MapEngine::shoot); stage 2 (CPU) applies each
// shot scan to the octree under the map lock (MapEngine::apply) and records it in the
// applied order. A hand-off of one slot between them lets stage 1 shoot scan k+1 while
// stage 2 applies scan k. Without pipelining, one thread runs both stages per scan.
#pragma once

#include <atomic>
#include <thread>

#include "daemon/bounded_handoff.h"
#include "daemon/map_state.h"
#include "daemon/pipeline_metrics.h"
#include "daemon/producer_registry.h"
#include "daemon/scan_queue.h"
#include "engine/map_engine.h"

namespace ort::daemon {

struct ShotJob {
  size_t producer = 0;
  std::string robot_id;
  int64_t seq = 0, utime = 0, points = 0;
  Clock::time_point received;
  double shoot_ms = 0;
  ShotScan shot;
  std::shared_ptr<MapEditItem> edit;  // set: apply this edit instead of a scan
};

class ScanPipeline {
 public:
  ScanPipeline(MapEngine& engine, MapState& map, ScanQueue& queue, ProducerRegistry& producers,
               PipelineMetrics& metrics, bool pipelined);
  ~ScanPipeline();
  void start();
  // Call after queue.close(): returns once every queued scan was applied or rejected.
  void join();
  size_t shot_depth() const { return handoff_.size(); }
  int64_t engine_errors() const { return engine_errors_; }

 private:
  // Stage 1 on one scan; false when it ended as a rejection.
  bool shoot(QueuedScan& item, ShotJob& job);
  void apply(ShotJob& job);
  void apply_edit(MapEditItem& edit);
  void reject(size_t producer, Reject why, const char* what);
  void run_stage1();
  void run_stage2();
  void run_sequential();

  MapEngine& engine_;
  MapState& map_;
  ScanQueue& queue_;
  ProducerRegistry& producers_;
  PipelineMetrics& metrics_;
  bool pipelined_;
  BoundedHandoff<ShotJob> handoff_{1};
  std::thread stage1_, stage2_;
  std::atomic<int64_t> engine_errors_{0};
};

}  // namespace ort::daemon
