// octomap-rt-server's logic, as a library so tests can run it in-process over memq://.
// It wires the parts: map (loaded from --map), engine, the LCM loop with the scan intake
// on it, the two-stage pipeline, the services that serve and answer from the map, the
// status reporter (daemon/status/status_reporter.h), the map saver (daemon/map_saver.h), and
// runs the lifecycle: start in order, the orderly stop (intake off, drain, save, loop off).
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <ostream>
#include <shared_mutex>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "core/clock.h"
#include "core/log.h"
#include "daemon/intake/producer_registry.h"
#include "daemon/intake/scan_intake.h"
#include "daemon/intake/scan_queue.h"
#include "daemon/map/change_journal.h"
#include "daemon/map/map_replica.h"
#include "daemon/map/map_residency.h"
#include "daemon/map/map_state.h"
#include "daemon/map/map_upkeep.h"
#include "daemon/map_saver.h"
#include "daemon/persistence/map_file_lock.h"
#include "daemon/persistence/map_identity_file.h"
#include "daemon/persistence/map_store.h"
#include "daemon/persistence/region_store.h"
#include "daemon/pipeline/pipeline_metrics.h"
#include "daemon/pipeline/scan_pipeline.h"
#include "daemon/queries/query_service.h"
#include "daemon/server_config.h"
#include "daemon/serving/delta_publisher.h"
#include "daemon/serving/map_service.h"
#include "daemon/serving/octomap_raw_publisher.h"
#include "daemon/status/degraded_causes.h"
#include "daemon/status/map_figures.h"
#include "daemon/status/status_message.h"
#include "daemon/status/status_reporter.h"
#include "daemon/transport/lcm_loop.h"
#include "octomap_rt/server_status_t.hpp"

namespace ort::daemon {

class MappingServer {
 public:
  // Own LCM on cfg.lcm_url (default: host-local udpm with a raised receive buffer).
  // Throws std::runtime_error with a clear message: map unreadable or of another
  // resolution, back end unavailable, LCM not usable.
  MappingServer(const ServerConfig& cfg, Log log);
  // On a shared LCM (tests: one memq:// instance shared with in-process producers). The
  // server's LCM loop is the only one that may call handle on it.
  MappingServer(const ServerConfig& cfg, lcm::LCM& shared, Log log);
  ~MappingServer();

  void start();
  // Intake off, queued scans applied for at most drain_timeout_s (the rest dropped: "left at
  // shutdown"), final save and status. Never throws; idempotent. Returns false when the
  // final save failed (final_save_error() says why; the summary prints it too).
  bool stop();
  const std::string& final_save_error() const { return final_save_error_; }

  // Saves now if the map changed since the last save (or `force`). Thread-safe.
  void save(bool force = false) { saver_->save(force); }

  octomap_rt::server_status_t status();
  std::vector<ProducerStats> producer_stats() const { return producers_.snapshot(); }
  std::vector<QueryClientStats> query_stats() const {
    return queries_ ? queries_->stats() : std::vector<QueryClientStats>{};
  }
  // How the distance field cache's entry was kept up to date (distance/field_cache.h).
  distance::FieldCacheStats distance_cache_stats() const {
    return queries_ ? queries_->service_stats().field_cache : distance::FieldCacheStats{};
  }
  std::optional<ChangeJournalStats> change_journal_stats() const {
    return journal_ ? std::optional(journal_->stats()) : std::nullopt;
  }
  // The applied order as the order file beside the map has it (synced first); without --map
  // the newest AppliedOrder::kRecent entries of this run.
  std::vector<AppliedEntry> applied_order() {
    if (cfg_.map_path.empty()) return map_.order.recent();
    map_.order.sync();
    return read_applied_order(cfg_.map_path + ".order").entries;
  }
  // Runs f(const OcTree&) under the map lock: a state between two whole scans.
  template <class F>
  auto with_map(F&& f) {
    std::shared_lock lock(map_.mutex);
    return f(static_cast<const octomap::OcTree&>(*map_.tree));
  }
  // Runs f(const OcTree&) on what whole-map readers read (the read replica, caught up with
  // the map as it is now; the map itself without one), under that map's lock.
  template <class F>
  auto with_readable_map(F&& f) {
    MapState& m = readable_map(map_);
    std::shared_lock lock(m.mutex);
    return f(static_cast<const octomap::OcTree&>(*m.tree));
  }
  // What snapshots, saves and the viewer map read: a version of the read replica at the map's
  // state now or newer (daemon/map/map_replica.h); null without a replica.
  std::shared_ptr<const ReplicaVersion> readable_version() { return daemon::readable_version(map_); }
  // Holds the read replica's lock (shared) until `release` is set, as a slow whole-map
  // reader would (tests: the octree stage goes on meanwhile). No-op without a replica.
  void hold_replica_until(const std::atomic<bool>& release) {
    if (!replica_) return;
    std::shared_lock lock(replica_->state().mutex);
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // Holds the map of record's lock (exclusive) until `release` is set, as stage 2 does for a
  // scan's update (tests: queries are answered from the read replica meanwhile).
  void hold_map_until(const std::atomic<bool>& release) {
    std::unique_lock lock(map_.mutex);
    while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // Who held the map of record's lock (and the replica's) the longest, and whom stage 2's
  // longest wait for it waited for (daemon/map/map_lock_holders.h).
  std::vector<LockHolderFigures> map_lock_holders() { return map_.holders.figures(); }
  std::vector<LockHolderFigures> replica_lock_holders() {
    return replica_ ? replica_->state().holders.figures() : std::vector<LockHolderFigures>{};
  }
  MetricsSnapshot pipeline_metrics() { return metrics_.snapshot(); }
  std::optional<ReplicaStats> replica_stats() const {
    return replica_ ? std::optional<ReplicaStats>(replica_->stats()) : std::nullopt;
  }
  const std::string& lcm_url() const { return url_; }
  // The whole map (evicted regions included: daemon/serving/map_snapshot.h), as a copy.
  std::unique_ptr<octomap::OcTree> whole_map();
  // The memory bound's figures (all 0 without --max-map-memory).
  MapResidencyStats residency_stats() const { return residency_ ? residency_->stats() : MapResidencyStats{}; }
  // Decay and clearing (null before start()); tests in manual mode step it through this.
  MapUpkeep* upkeep() { return upkeep_.get(); }
  // The server's one LCM thread: services register their raw handlers on it before start().
  LcmLoop& lcm_loop() { return *loop_; }
  // Human-readable end-of-run summary (per producer, stage times, overlap, map, files).
  void print_summary(std::ostream& out);

 private:
  MappingServer(const ServerConfig& cfg, lcm::LCM* shared, Log log);
  void load_or_create_map();
  // --max-map-memory: the region store (emptied: the map file holds what a previous run
  // evicted) and the residency, which brings a loaded map down to the bound.
  void open_memory_bound();
  // --max-map-memory while the map file loads: the store and residency opened first, and the
  // file split so that the tree is built within the bound (nullptr without a bound).
  const MapLoadBound* map_load_bound();
  void take_resolution_from_file();  // cfg_.resolution_from_file
  void open_map_serving();
  // The engine's warm-up scan (ServerConfig::warm_up_points), logged.
  void warm_up_engine();
  void drain_until_deadline(SteadyClock::time_point deadline);
  LoadedMapFile load_checked_map();  // tree nullptr: moved aside, start anew
  // The status' figures of now, gathered from every part (any thread).
  StatusInputs gather_status();
  DegradedSignals degraded_signals(const StatusInputs& in);

  ServerConfig cfg_;
  Log log_;
  std::string url_;
  MapFileLock map_lock_;                              // held from start to the end of the final save
  std::optional<MapIdentityRecord> loaded_identity_;  // the loaded map's, marked unclean
  std::unique_ptr<LcmLoop> loop_;
  std::unique_ptr<MapEngine> engine_;
  MapState map_;
  std::unique_ptr<RegionStore> region_store_;  // --max-map-memory's evicted regions
  std::unique_ptr<MapResidency> residency_;
  std::optional<MapLoadBound> load_bound_;
  std::unique_ptr<MapReplica> replica_;     // what whole-map readers read (cfg_.read_replica)
  std::unique_ptr<ChangeJournal> journal_;  // the scans' class changes, for the distance field cache
  ProducerRegistry producers_;
  ScanQueue queue_;
  PipelineMetrics metrics_;
  std::unique_ptr<ScanIntake> intake_;
  std::unique_ptr<ScanPipeline> pipeline_;
  std::unique_ptr<MapUpkeep> upkeep_;                   // decay, clearing by distance
  std::unique_ptr<QueryService> queries_;               // planners' queries and map edits
  std::unique_ptr<OctomapRawPublisher> raw_publisher_;  // the map for LCM viewers (off by default)
  std::unique_ptr<DeltaPublisher> deltas_;
  std::unique_ptr<MapService> map_service_;
  std::unique_ptr<MapSaver> saver_;
  std::unique_ptr<StatusReporter> status_;

  std::string host_, server_id_;
  int64_t start_utime_ = 0;
  SteadyClock::time_point start_;

  bool started_ = false, stopped_ = false;
  MapFigures map_figures_;
  std::atomic<bool> pipeline_drained_{false};  // set by stop() once the pipeline is joined
  std::string final_save_error_;               // "" unless the save at stop failed
};

}  // namespace ort::daemon
