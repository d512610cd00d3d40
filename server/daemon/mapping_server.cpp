#include "daemon/mapping_server.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <optional>

#include "core/clock.h"
#include "daemon/status/run_summary.h"
#include "daemon/transport/server_lcm_url.h"
#include "engine/engine_warm_up.h"

namespace ort::daemon {
namespace {

using Status = octomap_rt::server_status_t;

uint64_t queue_budget(const ServerConfig& c) {
  return c.queue_budget_bytes ? c.queue_budget_bytes : automatic_queue_budget();
}

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

}  // namespace

MappingServer::MappingServer(const ServerConfig& cfg, Log log) : MappingServer(cfg, nullptr, std::move(log)) {}
MappingServer::MappingServer(const ServerConfig& cfg, lcm::LCM& shared, Log log) : MappingServer(cfg, &shared, log) {}

MappingServer::MappingServer(const ServerConfig& cfg, lcm::LCM* shared, Log log)
    : cfg_(cfg),
      log_(std::move(log)),
      producers_(literal_prefix(cfg.scan_channels), producer_policy(cfg)),
      queue_(queue_budget(cfg), 8 * queue_budget(cfg), cfg.scan_costs.producer_share, cfg.scan_costs.shared_class_share,
             cfg.scan_costs.shared) {
  start_ = SteadyClock::now();
  start_utime_ = now_utime();
  host_ = host_name();
  server_id_ = cfg_.server_id.empty() ? "octomap-rt-server@" + host_ : cfg_.server_id;
  // A queue must hold at least one scan of the largest allowed size.
  const uint64_t largest = 12 * cfg_.max_points + 4096;
  if (queue_.per_producer_budget() < largest)
    throw std::runtime_error("queue budget " + std::to_string(queue_.per_producer_budget() >> 20) +
                             " MiB per producer cannot hold one scan of --max-points " +
                             std::to_string(cfg_.max_points));

  // First: a wrong or busy map file fails before any device is opened.
  if (!cfg_.map_path.empty()) map_lock_ = MapFileLock(cfg_.map_path, map_lock_holder(server_id_, host_));
  saver_ = std::make_unique<MapSaver>(cfg_.map_path, cfg_.save_interval_s, map_, log_);
  if (cfg_.resolution_from_file) take_resolution_from_file();
  load_or_create_map();
  open_memory_bound();
  // The leaves counted once, before anything reads or changes the map; from here on every
  // change keeps the count or forgets it (MapState::leaves).
  map_.leaves = static_cast<int64_t>(map_.tree->getNumLeafNodes());
  // The read replica would hold the whole map a memory bound keeps out of memory: with
  // --max-map-memory, readers read the map of record (as with --no-read-replica).
  if (cfg_.read_replica && cfg_.max_map_memory > 0)
    log_.info("a memory bound on: whole-map readers copy the map under its lock (no read replica)");
  else if (cfg_.read_replica) {
    OctreeUpdateOptions o = cfg_.engine.octree;
    // By default every hardware thread, the replica's helpers at the lowest priority: they
    // take what the octree stage leaves idle and yield to it (daemon/map/map_replica.h).
    o.threads = cfg_.replica_threads;
    o.helper_nice = 19;
    // Whole-map readers read versions of it kept per region (ServerConfig::replica_version_depth).
    replica_ = std::make_unique<MapReplica>(
        map_, o, cfg_.replica_pending_bytes, cfg_.replica_batch_voxels, cfg_.replica_nice,
        cfg_.replica_versions ? std::optional(region_grid(replica_version_depth(cfg_))) : std::nullopt,
        cfg_.replica_version_cells, cfg_.replica_batch_ms, cfg_.replica_rebuild_slice_nodes);
    map_.replica = replica_.get();
  }
  if (cfg_.queries.distance.field_cache && cfg_.queries.distance.change_lists) {
    journal_ = std::make_unique<ChangeJournal>();
    map_.journal = journal_.get();
  }
  engine_ = std::make_unique<MapEngine>(cfg_.engine, log_);
  if (!cfg_.applied_log.empty()) map_.order.open_live_log(cfg_.applied_log);

  if (shared) {
    url_ = "(shared LCM instance)";
    loop_ = std::make_unique<LcmLoop>(*shared, log_);
  } else {
    const LcmUrlChoice c = choose_lcm_url(cfg_.lcm_url, cfg_.recv_buf_size);
    url_ = c.url;
    if (!c.warning.empty()) log_.warning(c.warning);
    loop_ = std::make_unique<LcmLoop>(url_, log_);
  }
  StatusSources sources;
  sources.gather = [this] { return gather_status(); };
  sources.signals = [this](const StatusInputs& in) { return degraded_signals(in); };
  // The viewers' map cut or skipped for its size: said in every status.
  sources.note = [this] { return raw_publisher_ ? raw_publisher_->note() : std::string(); };
  StatusReporterConfig status = cfg_.status;
  status.running_message = "serving " + cfg_.scan_channels;
  status_ = std::make_unique<StatusReporter>(status, *loop_, std::move(sources), log_);
}

MappingServer::~MappingServer() {
  try {
    stop();
  } catch (const std::exception& e) {
    log_.error(text("while stopping: ", e.what()));
  }
}

void MappingServer::start() {
  if (started_) return;
  started_ = true;
  // From now until the last save of an orderly stop the identity says "unclean": a crash of
  // this run forks the history at the next start.
  if (loaded_identity_) saver_->write_identity(*loaded_identity_);
  ScanLimits limits;
  limits.max_points = cfg_.max_points;
  limits.resolution = cfg_.engine.resolution;
  limits.max_range = cfg_.engine.max_range;
  open_map_serving();  // the delta observer is in place before the first scan is applied
  warm_up_engine();    // before the pipeline's threads use the engine and before the intake opens
  pipeline_ = std::make_unique<ScanPipeline>(*engine_, map_, queue_, producers_, metrics_, log_, cfg_.pipeline,
                                             std::chrono::duration<double>(cfg_.latency_bound_s), cfg_.point_filters);
  pipeline_->set_cost_bounds(cfg_.scan_costs);
  pipeline_->set_shard(ShardFilter(cfg_.shard));
  if (cfg_.shard.sharded())
    log_.info(text("shard ", cfg_.shard.index, " of ", cfg_.shard.count, " (", protocol::to_string(cfg_.shard.rule),
                   " rule, regions at depth ", cfg_.shard.region_depth, "): only their voxels are mapped"));
  pipeline_->start();
  upkeep_ = std::make_unique<MapUpkeep>(map_, cfg_.upkeep, log_);
  upkeep_->start();
  intake_ =
      std::make_unique<ScanIntake>(*loop_, cfg_.scan_channels, limits, producers_, queue_, cfg_.lcm_queue_capacity);
  intake_->open();  // services subscribe before the loop starts: 1.3.1's subscribe races with handle
  map_service_->open();
  QueryServiceConfig query_cfg = cfg_.queries;
  query_cfg.distance.shard = cfg_.shard;  // a shard's distances count its own regions' obstacles
  query_cfg.shard = cfg_.shard;           // and its rays stop in its own regions only
  queries_ = std::make_unique<QueryService>(query_cfg, map_, queue_, *loop_, server_id_, cfg_.engine.resolution, log_);
  queries_->open();
  log_.info(text("distance queries run their EDT on ", queries_->distance_backend()));
  loop_->start();
  raw_publisher_ = std::make_unique<OctomapRawPublisher>(cfg_.octomap_raw, map_, *loop_, log_);
  raw_publisher_->start();
  map_service_->start();
  queries_->start();
  status_->start();
  saver_->start();
  status_->set_state(Status::STATE_RUNNING, "serving " + cfg_.scan_channels);
}

void MappingServer::warm_up_engine() {
  // No scan may be larger than --max-points: a bigger warm-up would size buffers for nothing.
  const size_t points = std::min<size_t>(cfg_.warm_up_points, cfg_.max_points);
  if (points == 0) return;
  try {
    const WarmUpReport w = warm_up(*engine_, points);
    char line[320];
    std::snprintf(
        line, sizeof line,
        "warmed up on a scan of %zu points (%llu voxels) on a scratch tree: stage 1 %.1f ms, stage 2 %.1f ms%s",
        w.points, (unsigned long long)w.voxels, w.shoot_ms, w.apply_ms,
        w.refused ? " (the engine refused the scan: the first scans may pay one-time costs)" : "");
    log_.info(line);
  } catch (const std::exception& e) {
    // The map is untouched either way; scans then meet the engine as they would have without.
    log_.warning(text("the warm-up failed (", e.what(), "); serving without it"));
  }
}

void MappingServer::open_map_serving() {
  if (cfg_.deltas.max_rate_hz > 0) {
    DeltaConfig d = cfg_.deltas;
    d.zstd_level = cfg_.serving.snapshots.zstd_level;  // one level and one pacing for all map bytes
    d.part_interval_ms = cfg_.serving.chunk_interval_ms;
    d.server_id = server_id_;
    d.resolution = cfg_.engine.resolution;
    deltas_ = std::make_unique<DeltaPublisher>(
        *loop_, d, [this] { return map_service_ ? map_service_->stats().latest_snapshot_id : -1; }, log_);
    map_.observer = deltas_.get();
    deltas_->start(map_.version, map_.epoch);
  }
  MapServiceConfig m = cfg_.serving;
  m.server_id = server_id_;
  m.resolution = cfg_.engine.resolution;
  // The part of space this server maps: the whole key space of its tree, or its shard box.
  const double half = 32768.0 * cfg_.engine.resolution;
  const double region_m = cfg_.engine.resolution * double(1u << (16 - cfg_.shard.region_depth));
  for (int k = 0; k < 3; ++k) {
    m.region_min[k] = -half;
    m.region_max[k] = half;
    if (cfg_.shard.rule == protocol::ShardRule::kBoxes) {
      const protocol::RegionBox& b = cfg_.shard.boxes[cfg_.shard.index];
      m.region_min[k] = b.min[k] * region_m - half;
      m.region_max[k] = b.max[k] * region_m - half;
    }
  }
  m.shard = cfg_.shard;
  map_service_ = std::make_unique<MapService>(
      *loop_, map_, m, [this] { return deltas_ ? deltas_->last_seq() : -1; }, log_);
}

bool MappingServer::stop() {
  if (!started_ || stopped_) return final_save_error_.empty();
  stopped_ = true;
  // The drain bound counts from the stop, not from the drain's start: closing the intake
  // waits for the LCM thread's handler in progress.
  const auto deadline = SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                                                 std::chrono::duration<double>(std::max(0.0, cfg_.drain_timeout_s)));
  status_->set_state(Status::STATE_STOPPING, "stopping: intake closed, draining queued scans");
  if (queries_) queries_->cut_running();  // no query holds the map past the drain bound
  intake_->close();
  queue_.close();
  drain_until_deadline(deadline);
  // The read replica stops here, its backlog left unapplied: stage 2 no longer waits for room
  // in it, the final save reads the map of record, and so do readers from now on (its
  // thread, at low priority, took minutes on a loaded machine to apply a backlog of big
  // scans that nothing would read).
  if (replica_) replica_->stop();
  pipeline_->join();
  pipeline_drained_ = true;
  if (upkeep_) upkeep_->stop();  // ends a sweep at its current slice (the map stays whole)
  if (deltas_) deltas_->stop();  // sends the last change set
  map_.observer = nullptr;
  saver_->stop();
  if (!cfg_.map_path.empty()) {
    status_->set_state(Status::STATE_STOPPING, "stopping: saving the map");
    // Nothing may throw before the threads below are joined: a failed final save is
    // reported (log, summary, status, exit status), not thrown.
    final_save_error_ = saver_->save_final();
  }
  status_->set_state(Status::STATE_STOPPING,
                     final_save_error_.empty() ? "stopped" : "stopped; the final save failed: " + final_save_error_);
  status_->stop();
  raw_publisher_->stop();
  map_service_->stop();
  if (queries_) queries_->stop();
  loop_->stop();
  if (replica_) replica_->stop();
  return final_save_error_.empty();
}

// The bounded drain: queued scans go through the pipeline until the queue is empty or the
// deadline passes; what is still queued then is dropped, counted ("left at shutdown").
// Scans already in the pipeline (at most two) are finished either way.
void MappingServer::drain_until_deadline(SteadyClock::time_point deadline) {
  while (queue_.depth() > 0 && SteadyClock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const std::vector<QueuedScan> left = queue_.take_all();
  size_t scans_left = 0;
  for (const QueuedScan& s : left) {
    if (s.edit) {  // its sender is told, and no producer counts it
      refuse_map_edit(*s.edit, EditRefusal::kNotApplied, "the server stopped before applying it (drain deadline)");
      continue;
    }
    producers_.count_dropped_in_flight(s.producer, Reject::kLeftAtShutdown);
    scans_left++;
  }
  if (!left.empty())
    log_.warning(text("drain deadline (", cfg_.drain_timeout_s, " s) passed: ", scans_left,
                      " queued scans dropped (left at shutdown), ", left.size() - scans_left,
                      " map edits refused; saving the map as applied"));
}

void MappingServer::print_summary(std::ostream& out) {
  RunSummaryInputs in;
  in.status = gather_status();
  in.scans_in_map = map_.order.size();
  in.applied_log = cfg_.applied_log;
  const SaveFigures saves = saver_->figures();
  in.last_save_ms = saves.last_save_ms;
  in.max_save_lock_ms = saves.max_save_lock_ms;
  if (map_service_) in.map_service = map_service_->stats();
  if (deltas_) in.deltas = deltas_->stats();
  in.deltas_on = deltas_ != nullptr;
  in.final_save_error = final_save_error_;
  print_run_summary(out, in);
  print_query_summary(out, query_stats());
}

}  // namespace ort::daemon
