// MappingServer's status: the figures gathered for OCTOMAP_RT_STATUS, the state rule
// (RUNNING / DEGRADED and why) applied once per status period, and the message published.
#include <unistd.h>

#include <chrono>
#include <shared_mutex>
#include <thread>

#include "core/clock.h"
#include "daemon/mapping_server.h"
#include "daemon/status/process_memory.h"
#include "daemon/transport/kernel_udp_stats.h"

namespace ort::daemon {

using Status = octomap_rt::server_status_t;

StatusInputs MappingServer::gather_status() {
  StatusInputs in;
  in.utime = now_utime();
  in.start_utime = start_utime_;
  in.uptime_s = seconds_since(start_);
  in.pid = static_cast<int32_t>(::getpid());
  in.server_id = server_id_;
  in.host = host_;
  in.backend = to_string(engine_->backend().kind());
  in.device = engine_->backend().device_name();
  in.map_path = cfg_.map_path;
  in.queue_policy = queue_.policy();
  in.pipelined = cfg_.pipeline;
  in.resolution = cfg_.engine.resolution;
  {
    // size() is O(1); the leaf count (and memoryUsage(), which needs it) walks the whole
    // tree under the map lock, stalling stage 2 for the whole walk (at 300 scans/s, several
    // scans' end-to-end time each second on big maps). So it is
    // walked only when the map changed, and then on maps above kLeafWalkEveryStatus nodes at
    // most every 10 s while scans are applied, and once more when the pipeline has drained
    // (the summary's figures are exact); memory comes from the cached leaf count with
    // OctoMap's formula.
    // The status never waits long for the map lock: a stage stuck while holding it must
    // still be reported (DEGRADED), so after ~100 ms the last figures are used again.
    // With the read replica the leaves are counted there (the octree stage never waits for
    // the walk), whenever the map changed and at most once a second.
    std::lock_guard cache_lock(leaf_cache_mutex_);
    if (map_.replica) {
      MapState& r = map_.replica->state();
      std::shared_lock rl(r.mutex, std::defer_lock);
      for (int i = 0; i < 100 && !rl.try_lock(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
      const auto now = SteadyClock::now();
      if (rl.owns_lock() && static_cast<int64_t>(r.version) != leaves_version_ &&
          (leaves_version_ < 0 || pipeline_drained_ || now - leaves_time_ >= std::chrono::seconds(1))) {
        cached_leaves_ = r.tree->getNumLeafNodes();
        leaves_time_ = now;
        leaves_version_ = static_cast<int64_t>(r.version);
      }
    }
    std::shared_lock lock(map_.mutex, std::defer_lock);
    for (int i = 0; i < 100 && !lock.try_lock(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (lock.owns_lock()) {
      const octomap::OcTree& t = *map_.tree;
      const auto now = SteadyClock::now();
      const int64_t version = static_cast<int64_t>(map_.version);
      if (!map_.replica && version != leaves_version_ &&
          (t.size() <= kLeafWalkEveryStatus || pipeline_drained_ || now - leaves_time_ > std::chrono::seconds(10))) {
        cached_leaves_ = t.getNumLeafNodes();
        leaves_time_ = now;
        leaves_version_ = version;
      }
      const size_t leaves = std::min(cached_leaves_.load(), t.size());
      cached_nodes_ = static_cast<int64_t>(t.size());
      cached_version_ = static_cast<int64_t>(map_.version);
      cached_epoch_ = static_cast<int64_t>(map_.epoch);
      cached_memory_ = static_cast<int64_t>(sizeof(octomap::OcTree) + t.memoryUsageNode() * t.size() +
                                            (t.size() - leaves) * sizeof(octomap::OcTreeNode* [8]));
    }
    in.map_version = cached_version_;
    in.map_epoch = cached_epoch_;
    in.num_nodes = cached_nodes_;
    in.num_leaf_nodes =
        static_cast<int64_t>(std::min<size_t>(cached_leaves_.load(), static_cast<size_t>(cached_nodes_.load())));
    in.memory_bytes = cached_memory_;
  }
  in.queue_depth = static_cast<int32_t>(queue_.depth());
  in.queue_bytes = static_cast<int64_t>(queue_.bytes());
  in.queue_budget_bytes = static_cast<int64_t>(queue_.per_producer_budget());
  in.shot_depth = pipeline_ ? static_cast<int32_t>(pipeline_->shot_depth()) : 0;
  in.kernel_rcvbuf_errors = read_udp_rcvbuf_errors();
  in.socket_rcvbuf_drops = read_own_udp_drops();
  in.lcm_handler_errors = loop_->handler_errors();
  if (residency_) {
    const MapResidencyStats r = residency_->stats();
    in.map_memory_bound = static_cast<int64_t>(r.max_bytes);
    in.resident_regions = static_cast<int64_t>(r.resident_regions);
    in.evicted_regions = static_cast<int64_t>(r.evicted_regions);
    in.evicted_bytes = static_cast<int64_t>(r.evicted_bytes);
    in.region_evictions = static_cast<int64_t>(r.evictions);
    in.region_restores = static_cast<int64_t>(r.restores);
    in.region_store_failures = static_cast<int64_t>(r.evict_failures + r.restore_failures);
    // The tree's memory as the bound counts it (between walks, the status' own leaf count lags).
    in.memory_bytes = static_cast<int64_t>(r.resident_bytes);
  }
  in.rss_bytes = resident_set_bytes();
  in.map_saves = saves_;
  if (map_service_) {
    const MapServiceStats ms = map_service_->stats();
    in.latest_snapshot_id = std::max<int64_t>(ms.latest_snapshot_id, 0);
    in.requests_served = ms.requests_served;
    in.requests_rejected = ms.requests_rejected;
    in.snapshots_taken = ms.snapshots_taken;
    in.chunks_sent = ms.chunks_sent;
  }
  if (deltas_) {
    const DeltaStats ds = deltas_->stats();
    in.deltas_sent = ds.messages;
    in.last_delta_seq = ds.last_seq;
  }
  in.last_save_utime = last_save_utime_;
  if (queries_) in.queries = queries_->service_stats();
  in.metrics = metrics_.snapshot();
  in.producers = producers_.snapshot();
  for (size_t i = 0; i < in.producers.size(); ++i)
    in.producer_queue_bytes.push_back(static_cast<int64_t>(queue_.producer_bytes(i)));
  std::lock_guard lock(state_mutex_);
  in.state = state_;
  in.message = message_;
  in.seq = status_seq_;
  in.shard = cfg_.shard;
  return in;
}

octomap_rt::server_status_t MappingServer::status() { return make_status(gather_status()); }

void MappingServer::publish_status() {
  StatusInputs in = gather_status();
  const std::string why = degraded_.causes(degraded_signals(in));
  {
    std::lock_guard lock(state_mutex_);
    if (loop_->failed()) {
      state_ = Status::STATE_ERROR;
      message_ = "LCM intake failed; no scans are received";
    } else if (state_ == Status::STATE_RUNNING && !why.empty()) {
      state_ = Status::STATE_DEGRADED;
      message_ = "degraded: " + why;
    } else if (state_ == Status::STATE_DEGRADED) {
      if (why.empty()) {
        state_ = Status::STATE_RUNNING;
        message_ = "serving " + cfg_.scan_channels;
      } else {
        message_ = "degraded: " + why;
      }
    }
    in.state = state_;
    in.message = message_;
    in.seq = status_seq_++;
  }
  // The viewers' map cut or skipped for its size: said in every status.
  if (const std::string note = raw_publisher_ ? raw_publisher_->note() : ""; !note.empty()) in.message += "; " + note;
  const octomap_rt::server_status_t msg = make_status(in);
  loop_->publish(cfg_.status_channel, msg);
}

// The state rule's inputs for this status period (DegradedTracker says why, if at all).
DegradedSignals MappingServer::degraded_signals(const StatusInputs& in) {
  DegradedSignals s;
  {
    std::lock_guard lock(state_mutex_);
    s.save_error = last_save_error_;
  }
  s.longest_busy_s = pipeline_ ? std::chrono::duration<double>(pipeline_->longest_busy()).count() : 0.0;
  s.stuck_stage_s = cfg_.stuck_stage_s;
  s.queue_bytes = queue_.bytes();
  s.queue_total_budget = queue_.total_budget();
  s.oldest_queued_s = std::chrono::duration<double>(queue_.oldest_age()).count();
  s.latency_bound_s = cfg_.latency_bound_s;
  s.e2e_p99_ms = in.metrics.e2e_p99;
  for (const ProducerStats& p : in.producers) {
    s.scans_dropped += p.dropped;
    s.scans_rejected += p.rejected;
  }
  // The server's own socket drops when known (the namespace-wide count includes clients).
  s.kernel_drops = in.socket_rcvbuf_drops >= 0 ? in.socket_rcvbuf_drops : in.kernel_rcvbuf_errors;
  return s;
}

}  // namespace ort::daemon
