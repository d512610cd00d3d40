// Assembles the server_status_t heartbeat from plain values the server gathers.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "daemon/intake/producer_registry.h"
#include "daemon/pipeline/pipeline_metrics.h"
#include "daemon/queries/query_clients.h"
#include "octomap_rt/server_status_t.hpp"
#include "protocol/shards/shard_set.h"

namespace ort::daemon {

struct StatusInputs {
  protocol::ShardSet shard;  // the shard set this server belongs to (announced in every status)
  int64_t utime = 0, seq = 0, start_utime = 0;
  int32_t pid = 0;
  double uptime_s = 0;
  int8_t state = octomap_rt::server_status_t::STATE_STARTING;
  std::string message;
  std::string server_id, host, backend, device, map_path, queue_policy;
  bool pipelined = true;
  double resolution = 0;
  int64_t num_nodes = 0, num_leaf_nodes = 0, memory_bytes = 0;
  int32_t queue_depth = 0, shot_depth = 0;
  int64_t queue_bytes = 0, queue_budget_bytes = 0;
  int64_t kernel_rcvbuf_errors = -1, socket_rcvbuf_drops = -1;
  int64_t lcm_handler_errors = 0;  // LcmLoop::handler_errors()
  // The memory bound (daemon/map/map_residency.h) and the process's RSS.
  int64_t map_memory_bound = 0, resident_regions = 0, evicted_regions = 0, evicted_bytes = 0;
  int64_t region_evictions = 0, region_restores = 0, region_store_failures = 0, rss_bytes = -1;
  int64_t evict_passes = 0;
  double evict_ms = 0, evict_count_ms = 0, evict_ms_max = 0, restore_ms = 0, restore_ms_max = 0;
  int64_t map_saves = 0, last_save_utime = 0;
  int64_t map_version = 0, map_epoch = 0, latest_snapshot_id = 0, requests_served = 0, requests_rejected = 0;
  int64_t snapshots_taken = 0, chunks_sent = 0, deltas_sent = 0, last_delta_seq = -1;
  MetricsSnapshot metrics;
  std::vector<ProducerStats> producers;
  std::vector<int64_t> producer_queue_bytes;  // parallel to producers
  QueryServiceStats queries;
};

// Clients listed in server_status_t.query_clients (those heard from most recently); the
// totals count every client.
constexpr size_t kStatusQueryClients = 64;

octomap_rt::server_status_t make_status(const StatusInputs& in);

}  // namespace ort::daemon
