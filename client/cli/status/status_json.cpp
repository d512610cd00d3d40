#include "cli/status/status_json.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "cli/status/status_text.h"

namespace ort::status {
namespace {

// A JSON object written field by field; close() gives it with its braces.
class JsonObject {
 public:
  JsonObject& raw(const char* key, const std::string& json) {
    if (text_.size() > 1) text_ += ',';
    text_ += '"';
    text_ += key;
    text_ += "\":";
    text_ += json;
    return *this;
  }
  JsonObject& num(const char* key, int64_t v) { return raw(key, std::to_string(v)); }
  JsonObject& num(const char* key, double v) {
    if (!std::isfinite(v)) return raw(key, "null");  // JSON has no NaN or infinity
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return raw(key, buf);
  }
  JsonObject& str(const char* key, const std::string& v) { return raw(key, json_string(v)); }
  JsonObject& flag(const char* key, bool v) { return raw(key, v ? "true" : "false"); }
  std::string close() const { return text_ + "}"; }

 private:
  std::string text_ = "{";
};

// {"name":count,...} from a message's parallel lists of reasons and their counts.
std::string counts_json(const std::vector<std::string>& names, const std::vector<int64_t>& counts) {
  std::string out = "{";
  for (size_t i = 0; i < std::min(names.size(), counts.size()); ++i)
    out += (i ? "," : "") + json_string(names[i]) + ":" + std::to_string(counts[i]);
  return out + "}";
}

// [item,...] with each item written by `to_json`.
template <class Item, class ToJson>
std::string array_json(const std::vector<Item>& items, ToJson to_json) {
  std::string out = "[";
  for (size_t i = 0; i < items.size(); ++i) out += (i ? "," : "") + to_json(items[i]);
  return out + "]";
}

std::string robot_json(const octomap_rt::robot_stats_t& r) {
  return JsonObject()
      .str("robot_id", r.robot_id)
      .str("channel", r.channel)
      .num("last_scan_utime", r.last_scan_utime)
      .num("last_seq", r.last_seq)
      .num("scans_received", r.scans_received)
      .num("scans_applied", r.scans_applied)
      .num("scans_rejected", r.scans_rejected)
      .num("scans_dropped", r.scans_dropped)
      .num("scans_missed", r.scans_missed)
      .num("seq_restarts", r.seq_restarts)
      .num("points_applied", r.points_applied)
      .num("queue_depth", int64_t(r.queue_depth))
      .num("queue_bytes", r.queue_bytes)
      .num("last_end_to_end_ms", double(r.last_end_to_end_ms))
      .raw("reject_reasons", counts_json(r.reject_reason, r.reject_count))
      .raw("drop_reasons", counts_json(r.drop_reason, r.drop_count))
      .raw("point_drops", counts_json(r.point_drop_reason, r.point_drop_count))
      .num("points_read_as_zero", r.points_read_as_zero)
      .close();
}

std::string query_client_json(const octomap_rt::query_client_stats_t& c) {
  return JsonObject()
      .str("client_id", c.client_id)
      .str("reply_channel", c.reply_channel)
      .num("received", c.received)
      .num("answered", c.answered)
      .num("bad", c.bad)
      .num("busy", c.busy)
      .num("not_ready", c.not_ready)
      .num("dropped", c.dropped)
      .num("edits_applied", c.edits_applied)
      .num("edits_refused", c.edits_refused)
      .num("queue_depth", int64_t(c.queue_depth))
      .num("last_utime", c.last_utime)
      .str("last_error", c.last_error)
      .close();
}

// "queries": totals, refusal reasons (name -> count) and the clients.
std::string queries_json(const octomap_rt::server_status_t& s) {
  return JsonObject()
      .num("received", s.queries_received)
      .num("answered", s.queries_answered)
      .num("bad", s.queries_bad)
      .num("busy", s.queries_busy)
      .num("not_ready", s.queries_not_ready)
      .num("dropped", s.queries_dropped)
      .num("edits_applied", s.edits_applied)
      .num("edits_refused", s.edits_refused)
      .num("grids_published", s.grids_published)
      .raw("refusal_reasons", counts_json(s.query_refusal_reason, s.query_refusal_count))
      .raw("clients", array_json(s.query_clients, query_client_json))
      .close();
}

}  // namespace

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (unsigned char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += char(c);
    } else if (c < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += char(c);
    }
  }
  return out + "\"";
}

std::string status_json(const octomap_rt::server_status_t& s) {
  return JsonObject()
      .num("utime", s.utime)
      .num("seq", s.seq)
      .str("server_id", s.server_id)
      .str("host", s.host)
      .num("pid", int64_t(s.pid))
      .num("start_utime", s.start_utime)
      .num("uptime_s", s.uptime_s)
      .num("state", int64_t(s.state))
      .str("state_name", state_name(s.state))
      .str("message", s.message)
      .str("backend", s.backend)
      .str("device", s.device)
      .flag("pipelined", s.pipelined)
      .num("resolution", s.resolution)
      .num("num_nodes", s.num_nodes)
      .num("num_leaf_nodes", s.num_leaf_nodes)
      .num("memory_bytes", s.memory_bytes)
      .str("map_path", s.map_path)
      .num("map_saves", s.map_saves)
      .num("last_save_utime", s.last_save_utime)
      .num("scan_queue_depth", int64_t(s.scan_queue_depth))
      .num("scan_queue_bytes", s.scan_queue_bytes)
      .num("queue_budget_bytes", s.queue_budget_bytes)
      .str("queue_policy", s.queue_policy)
      .num("shot_queue_depth", int64_t(s.shot_queue_depth))
      .num("scans_applied", s.scans_applied)
      .num("points_applied", s.points_applied)
      .num("scans_per_s", double(s.scans_per_s))
      .num("points_per_s", double(s.points_per_s))
      .num("shoot_ms_p50", double(s.shoot_ms_p50))
      .num("shoot_ms_p99", double(s.shoot_ms_p99))
      .num("octree_ms_p50", double(s.octree_ms_p50))
      .num("octree_ms_p99", double(s.octree_ms_p99))
      .num("end_to_end_ms_p50", double(s.end_to_end_ms_p50))
      .num("end_to_end_ms_p99", double(s.end_to_end_ms_p99))
      .num("stage1_busy_s", s.stage1_busy_s)
      .num("stage2_busy_s", s.stage2_busy_s)
      .num("overlap_busy_s", s.overlap_busy_s)
      .num("overlapped_scans", s.overlapped_scans)
      .num("kernel_rcvbuf_errors", s.kernel_rcvbuf_errors)
      .num("socket_rcvbuf_drops", s.socket_rcvbuf_drops)
      .num("lcm_handler_errors", s.lcm_handler_errors)
      .num("map_memory_bound", s.map_memory_bound)
      .num("resident_regions", s.resident_regions)
      .num("evicted_regions", s.evicted_regions)
      .num("evicted_bytes", s.evicted_bytes)
      .num("region_evictions", s.region_evictions)
      .num("region_restores", s.region_restores)
      .num("region_store_failures", s.region_store_failures)
      .num("rss_bytes", s.rss_bytes)
      .num("evict_passes", s.evict_passes)
      .num("evict_ms", s.evict_ms)
      .num("evict_count_ms", s.evict_count_ms)
      .num("evict_ms_max", s.evict_ms_max)
      .num("restore_ms", s.restore_ms)
      .num("restore_ms_max", s.restore_ms_max)
      .num("distance_fields_whole", s.distance_fields_whole)
      .num("distance_fields_partial", s.distance_fields_partial)
      .num("distance_fields_unchanged", s.distance_fields_unchanged)
      .num("distance_patched", s.distance_patched)
      .num("distance_patch_changes", s.distance_patch_changes)
      .num("distance_reread", s.distance_reread)
      .num("distance_replies_kept", s.distance_replies_kept)
      .num("distance_frames", s.distance_frames)
      .num("distance_frames_kept", s.distance_frames_kept)
      .num("map_version", s.map_version)
      .num("latest_snapshot_id", s.latest_snapshot_id)
      .num("snapshots_taken", s.snapshots_taken)
      .num("requests_served", s.requests_served)
      .num("requests_rejected", s.requests_rejected)
      .num("chunks_sent", s.chunks_sent)
      .num("deltas_sent", s.deltas_sent)
      .num("last_delta_seq", s.last_delta_seq)
      .raw("robots", array_json(s.robots, robot_json))
      .raw("queries", queries_json(s))
      .close();
}

}  // namespace ort::status
