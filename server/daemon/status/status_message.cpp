#include "daemon/status/status_message.h"
#include "protocol/shards/shard_wire.h"

#include <algorithm>
#include <array>

#include "protocol/version.h"

namespace ort::daemon {
namespace {

octomap_rt::query_client_stats_t client_message(const QueryClientStats& c) {
  octomap_rt::query_client_stats_t m;
  m.received = c.received;
  m.answered = c.answered;
  m.cut = c.cut;
  m.bad = c.bad;
  m.busy = c.busy;
  m.not_ready = c.not_ready;
  m.dropped = c.dropped;
  m.edits_applied = c.edits_applied;
  m.edits_refused = c.edits_refused;
  m.last_utime = c.last_utime;
  m.queue_depth = static_cast<int32_t>(c.queue_depth);
  m.client_id = c.client_id;
  m.reply_channel = c.reply_channel;
  m.last_error = c.last_error;
  return m;
}

// The reasons counted at least once, by name, in the order of their enum; returns how many.
template <typename Reason, size_t N>
int32_t add_reasons(const std::array<int64_t, N>& counted, std::vector<std::string>& names,
                    std::vector<int64_t>& counts) {
  for (size_t k = 0; k < N; ++k) {
    if (counted[k] == 0) continue;
    names.push_back(to_string(static_cast<Reason>(k)));
    counts.push_back(counted[k]);
  }
  return static_cast<int32_t>(names.size());
}

octomap_rt::robot_stats_t robot_message(const ProducerStats& p, int64_t queue_bytes) {
  octomap_rt::robot_stats_t r;
  r.last_scan_utime = p.last_utime;
  r.last_seq = p.last_seq;
  r.scans_received = p.received;
  r.scans_applied = p.applied;
  r.scans_rejected = p.rejected;
  r.scans_dropped = p.dropped;
  r.scans_missed = p.missed;
  r.points_applied = p.points_applied;
  r.queue_depth = static_cast<int32_t>(p.in_flight);
  r.queue_bytes = queue_bytes;
  r.last_end_to_end_ms = static_cast<float>(p.last_end_to_end_ms);
  r.num_reject_reasons = add_reasons<Reject>(p.rejects, r.reject_reason, r.reject_count);
  r.num_drop_reasons = add_reasons<Reject>(p.drop_reasons, r.drop_reason, r.drop_count);
  r.num_point_drop_reasons = add_reasons<PointDrop>(p.point_drops, r.point_drop_reason, r.point_drop_count);
  r.points_read_as_zero = p.points_read_as_zero;
  r.seq_restarts = p.seq_restarts;
  r.robot_id = p.robot_id;
  r.channel = p.channel;
  return r;
}

void add_queries(octomap_rt::server_status_t& s, const QueryServiceStats& q) {
  s.queries_received = s.queries_answered = s.queries_cut = s.queries_bad = s.queries_busy = s.queries_not_ready = 0;
  s.queries_dropped = s.edits_applied = s.edits_refused = 0;
  for (const QueryClientStats& c : q.clients) {
    s.queries_received += c.received;
    s.queries_answered += c.answered;
    s.queries_cut += c.cut;
    s.queries_bad += c.bad;
    s.queries_busy += c.busy;
    s.queries_not_ready += c.not_ready;
    s.queries_dropped += c.dropped;
    s.edits_applied += c.edits_applied;
    s.edits_refused += c.edits_refused;
  }
  s.grids_published = q.grids_published;
  for (const auto& [reason, n] : q.refusal_reasons) {
    s.query_refusal_reason.push_back(reason);
    s.query_refusal_count.push_back(n);
  }
  s.num_query_refusal_reasons = static_cast<int32_t>(s.query_refusal_reason.size());
  std::vector<const QueryClientStats*> recent;
  for (const QueryClientStats& c : q.clients) recent.push_back(&c);
  const size_t n = std::min(recent.size(), kStatusQueryClients);
  std::partial_sort(recent.begin(), recent.begin() + n, recent.end(),
                    [](auto* a, auto* b) { return a->last_utime > b->last_utime; });
  recent.resize(n);
  std::sort(recent.begin(), recent.end(), [](auto* a, auto* b) { return a->client_id < b->client_id; });
  for (const QueryClientStats* c : recent) s.query_clients.push_back(client_message(*c));
  s.num_query_clients = static_cast<int32_t>(s.query_clients.size());
}

}  // namespace

octomap_rt::server_status_t make_status(const StatusInputs& in) {
  octomap_rt::server_status_t s;
  s.protocol_version = protocol::kProtocolVersion;
  protocol::put_shard_set(in.shard, s);
  s.utime = in.utime;
  s.seq = in.seq;
  s.start_utime = in.start_utime;
  s.uptime_s = in.uptime_s;
  s.pid = in.pid;
  s.state = in.state;
  s.pipelined = in.pipelined;
  s.resolution = in.resolution;
  s.num_nodes = in.num_nodes;
  s.num_leaf_nodes = in.num_leaf_nodes;
  s.memory_bytes = in.memory_bytes;
  s.scan_queue_depth = in.queue_depth;
  s.scan_queue_bytes = in.queue_bytes;
  s.queue_budget_bytes = in.queue_budget_bytes;
  s.shot_queue_depth = in.shot_depth;
  const MetricsSnapshot& m = in.metrics;
  s.scans_applied = m.scans_applied;
  s.points_applied = m.points_applied;
  s.scans_per_s = static_cast<float>(m.scans_per_s);
  s.points_per_s = static_cast<float>(m.points_per_s);
  s.shoot_ms_p50 = static_cast<float>(m.shoot_p50);
  s.shoot_ms_p99 = static_cast<float>(m.shoot_p99);
  s.octree_ms_p50 = static_cast<float>(m.octree_p50);
  s.octree_ms_p99 = static_cast<float>(m.octree_p99);
  s.octree_lock_wait_ms_p99 = static_cast<float>(m.lock_wait.p99);
  s.octree_lock_wait_ms_max = static_cast<float>(m.lock_wait_max);
  s.end_to_end_ms_p50 = static_cast<float>(m.e2e_p50);
  s.end_to_end_ms_p99 = static_cast<float>(m.e2e_p99);
  s.stage1_busy_s = m.overlap.busy_s[0];
  s.stage2_busy_s = m.overlap.busy_s[1];
  s.overlap_busy_s = m.overlap.both_s;
  s.overlapped_scans = m.overlapped_scans;
  s.kernel_rcvbuf_errors = in.kernel_rcvbuf_errors;
  s.socket_rcvbuf_drops = in.socket_rcvbuf_drops;
  s.lcm_handler_errors = in.lcm_handler_errors;
  s.map_memory_bound = in.map_memory_bound;
  s.resident_regions = in.resident_regions;
  s.evicted_regions = in.evicted_regions;
  s.evicted_bytes = in.evicted_bytes;
  s.region_evictions = in.region_evictions;
  s.region_restores = in.region_restores;
  s.region_store_failures = in.region_store_failures;
  s.rss_bytes = in.rss_bytes;
  s.evict_passes = in.evict_passes;
  s.evict_ms = in.evict_ms;
  s.evict_count_ms = in.evict_count_ms;
  s.evict_ms_max = in.evict_ms_max;
  s.restore_ms = in.restore_ms;
  s.restore_ms_max = in.restore_ms_max;
  const distance::FieldCacheStats& fc = in.queries.field_cache;
  s.distance_fields_whole = fc.full;
  s.distance_fields_partial = fc.partial;
  s.distance_fields_unchanged = fc.unchanged;
  s.distance_patched = fc.patched;
  s.distance_patch_changes = fc.patch_changes;
  s.distance_reread = fc.reread;
  s.distance_replies_kept = fc.replies_kept;
  s.distance_frames = fc.frames;
  s.distance_frames_kept = fc.frames_kept;
  s.map_saves = in.map_saves;
  s.last_save_utime = in.last_save_utime;
  s.latest_snapshot_id = in.latest_snapshot_id;
  s.map_version = in.map_version;
  s.map_epoch = in.map_epoch;
  s.requests_served = in.requests_served;
  s.requests_rejected = in.requests_rejected;
  s.snapshots_taken = in.snapshots_taken;
  s.chunks_sent = in.chunks_sent;
  s.deltas_sent = in.deltas_sent;
  s.last_delta_seq = in.last_delta_seq;
  for (size_t i = 0; i < in.producers.size(); ++i)
    s.robots.push_back(
        robot_message(in.producers[i], i < in.producer_queue_bytes.size() ? in.producer_queue_bytes[i] : 0));
  s.num_robots = static_cast<int32_t>(s.robots.size());
  s.server_id = in.server_id;
  s.host = in.host;
  s.backend = in.backend;
  s.device = in.device;
  s.map_path = in.map_path;
  s.queue_policy = in.queue_policy;
  s.message = in.message;
  add_queries(s, in.queries);
  return s;
}

}  // namespace ort::daemon
