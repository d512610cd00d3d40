// MappingServer's status: the figures gathered from every part for OCTOMAP_RT_STATUS and the
// state rule's inputs; the StatusReporter (daemon/status/status_reporter.h) applies the rule
// and publishes.
#include <unistd.h>

#include <chrono>

#include "core/clock.h"
#include "daemon/mapping_server.h"
#include "daemon/status/process_memory.h"
#include "daemon/transport/kernel_udp_stats.h"

namespace ort::daemon {

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
  const MapSize size = map_figures_.read(map_, pipeline_drained_);
  in.map_version = size.version;
  in.map_epoch = size.epoch;
  in.num_nodes = size.nodes;
  in.num_leaf_nodes = size.leaves;
  in.memory_bytes = size.memory_bytes;
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
    in.evict_passes = static_cast<int64_t>(r.enforce_passes);
    in.evict_ms = r.enforce_ms;
    in.evict_count_ms = r.walk_ms;
    in.evict_ms_max = r.longest_enforce_ms;
    in.restore_ms = r.touch_ms;
    in.restore_ms_max = r.longest_touch_ms;
    // The tree's memory as the bound counts it (between walks, the status' own leaf count lags).
    in.memory_bytes = static_cast<int64_t>(r.resident_bytes);
  }
  in.rss_bytes = resident_set_bytes();
  const SaveFigures saves = saver_->figures();
  in.map_saves = saves.saves;
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
  in.last_save_utime = saves.last_save_utime;
  if (queries_) in.queries = queries_->service_stats();
  in.metrics = metrics_.snapshot();
  in.producers = producers_.snapshot();
  for (size_t i = 0; i < in.producers.size(); ++i)
    in.producer_queue_bytes.push_back(static_cast<int64_t>(queue_.producer_bytes(i)));
  in.shard = cfg_.shard;
  status_->stamp(in);
  return in;
}

octomap_rt::server_status_t MappingServer::status() { return make_status(gather_status()); }

// The state rule's inputs for this status period (DegradedTracker says why, if at all).
DegradedSignals MappingServer::degraded_signals(const StatusInputs& in) {
  DegradedSignals s;
  s.save_error = saver_->figures().last_error;
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
