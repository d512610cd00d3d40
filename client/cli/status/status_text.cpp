#include "cli/status/status_text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace ort::status {
namespace {

using Status = octomap_rt::server_status_t;

std::string fmt(const char* format, auto... args) {
  char buf[256];
  std::snprintf(buf, sizeof buf, format, args...);
  return buf;
}

std::string age_text(int64_t then_utime, int64_t now_utime) {
  if (then_utime <= 0) return "never";
  return duration_text(std::max<double>(0, double(now_utime - then_utime) / 1e6)) + " ago";
}

void header(std::ostringstream& o, const Status& s, int64_t now) {
  o << fmt("%s (pid %d on %s)   state %s   up %s   status #%lld, %s\n", s.server_id.c_str(), s.pid, s.host.c_str(),
           state_name(s.state).c_str(), duration_text(s.uptime_s).c_str(), (long long)s.seq,
           age_text(s.utime, now).c_str());
  if (!s.message.empty()) o << "  message   " << s.message << "\n";
}

void engine_and_map(std::ostringstream& o, const Status& s, int64_t now) {
  o << "  back end  " << s.backend << " on " << s.device << (s.pipelined ? ", pipelined" : ", not pipelined") << "\n";
  o << fmt("  map       %.3g m, %s nodes, %s leaves, %s; %lld saves, last %s\n", s.resolution,
           with_commas(s.num_nodes).c_str(), with_commas(s.num_leaf_nodes).c_str(), bytes_text(s.memory_bytes).c_str(),
           (long long)s.map_saves, age_text(s.last_save_utime, now).c_str());
  if (!s.map_path.empty()) o << "  map file  " << s.map_path << "\n";
}

void rates_and_latencies(std::ostringstream& o, const Status& s) {
  o << fmt("  rates     %s scans/s, %s points/s; applied %s scans, %s points\n", rate_text(s.scans_per_s).c_str(),
           rate_text(s.points_per_s).c_str(), with_commas(s.scans_applied).c_str(),
           with_commas(s.points_applied).c_str());
  o << fmt("  latency   p50 / p99 ms: shoot %.1f / %.1f   octree %.1f / %.1f   end to end %.1f / %.1f\n",
           s.shoot_ms_p50, s.shoot_ms_p99, s.octree_ms_p50, s.octree_ms_p99, s.end_to_end_ms_p50, s.end_to_end_ms_p99);
  o << fmt("  overlap   busy: stage 1 %.1f s, stage 2 %.1f s, both %.1f s (%s scans overlapped)\n", s.stage1_busy_s,
           s.stage2_busy_s, s.overlap_busy_s, with_commas(s.overlapped_scans).c_str());
}

void queue_and_kernel(std::ostringstream& o, const Status& s) {
  o << fmt("  queue     %d scans, %s (budget %s per producer); %d shot, waiting for the octree\n", s.scan_queue_depth,
           bytes_text(s.scan_queue_bytes).c_str(), bytes_text(s.queue_budget_bytes).c_str(), s.shot_queue_depth);
  auto known = [](int64_t v) { return v < 0 ? std::string("unknown") : with_commas(v); };
  o << "  UDP       receive-buffer errors " << known(s.kernel_rcvbuf_errors) << " (all sockets), "
    << known(s.socket_rcvbuf_drops) << " dropped on the server's sockets\n";
  if (s.lcm_handler_errors > 0)
    o << "  LCM       " << with_commas(s.lcm_handler_errors)
      << " messages whose handler failed (see the server's log)\n";
  if (s.map_memory_bound > 0)
    o << "  memory    bound " << bytes_text(s.map_memory_bound) << ": " << bytes_text(s.memory_bytes) << " resident in "
      << with_commas(s.resident_regions) << " regions, " << with_commas(s.evicted_regions) << " regions evicted ("
      << bytes_text(s.evicted_bytes) << " in the store); " << with_commas(s.region_evictions) << " evictions, "
      << with_commas(s.region_restores) << " restores, " << with_commas(s.region_store_failures)
      << " refused by the store; RSS " << (s.rss_bytes < 0 ? std::string("unknown") : bytes_text(s.rss_bytes)) << "\n"
      << fmt("  bound     %s passes %.1f ms (exact counts %.1f, longest %.1f); restores %.1f ms (longest %.1f a "
             "scan)\n",
             with_commas(s.evict_passes).c_str(), s.evict_ms, s.evict_count_ms, s.evict_ms_max, s.restore_ms,
             s.restore_ms_max);
}

// The map service (snapshots, chunks) and the delta stream: what mirrors and map clients got.
void serving(std::ostringstream& o, const Status& s) {
  const std::string snapshot = s.latest_snapshot_id > 0 ? "#" + with_commas(s.latest_snapshot_id) : "none";
  const std::string delta = s.last_delta_seq >= 0 ? "last seq " + with_commas(s.last_delta_seq) : "none yet";
  o << fmt("  serving   map version %s, latest snapshot %s (%s taken); requests %s served, %s rejected\n",
           with_commas(s.map_version).c_str(), snapshot.c_str(), with_commas(s.snapshots_taken).c_str(),
           with_commas(s.requests_served).c_str(), with_commas(s.requests_rejected).c_str());
  o << fmt("  sent      %s snapshot chunks, %s deltas (%s)\n", with_commas(s.chunks_sent).c_str(),
           with_commas(s.deltas_sent).c_str(), delta.c_str());
}

// One robot's counts by reason on a line of their own ("    rejected: truncated 2, ..."), none
// when there are none.
void reasons(std::ostringstream& o, const char* what, const std::vector<std::string>& names,
             const std::vector<int64_t>& counts) {
  const size_t n = std::min(names.size(), counts.size());
  if (n == 0) return;
  o << "    " << what << ":";
  for (size_t i = 0; i < n; ++i) o << (i ? ", " : " ") << names[i] << " " << with_commas(counts[i]);
  o << "\n";
}

void robots(std::ostringstream& o, const Status& s, int64_t now) {
  if (s.robots.empty()) {
    o << "\n  no robots yet (scans on OCTOMAP_RT_SCAN_<ROBOT>)\n";
    return;
  }
  o << fmt("\n  %-12s %9s %9s %8s %8s %7s %6s %9s %8s %10s\n", "robot", "received", "applied", "rejected", "dropped",
           "missed", "queued", "last seq", "e2e ms", "last scan");
  for (const auto& r : s.robots) {
    o << fmt("  %-12s %9s %9s %8s %8s %7s %6d %9lld %8.1f %10s\n", r.robot_id.c_str(),
             with_commas(r.scans_received).c_str(), with_commas(r.scans_applied).c_str(),
             with_commas(r.scans_rejected).c_str(), with_commas(r.scans_dropped).c_str(),
             with_commas(r.scans_missed).c_str(), r.queue_depth, (long long)r.last_seq, r.last_end_to_end_ms,
             age_text(r.last_scan_utime, now).c_str());
    // A robot that restarted (its seq went back to 0 or jumped) is worth a line: its gaps
    // before and after are not lost scans.
    if (r.seq_restarts > 0) o << "    seq restarts: " << with_commas(r.seq_restarts) << "\n";
    reasons(o, "rejected", r.reject_reason, r.reject_count);
    reasons(o, "dropped", r.drop_reason, r.drop_count);
    reasons(o, "points without a ray", r.point_drop_reason, r.point_drop_count);
    // Subnormal or tiny coordinates are read as 0 (docs/PROTOCOL.md, "Coordinates near 0"):
    // rays all the same, but a producer that sends them is worth a look.
    if (r.points_read_as_zero > 0)
      o << "    points read as 0 (a coordinate below 1e-20 m): " << with_commas(r.points_read_as_zero) << "\n";
  }
}

void queries(std::ostringstream& o, const Status& s, int64_t now) {
  if (s.queries_received == 0 && s.queries_dropped == 0 && s.grids_published == 0) {
    o << "  queries   none yet (OCTOMAP_RT_QUERY...)\n";
    return;
  }
  o << fmt(
      "  queries   received %s: answered %s, bad %s, busy %s, not ready %s; dropped %s; edits %s applied, %s "
      "refused; grids published %s\n",
      with_commas(s.queries_received).c_str(), with_commas(s.queries_answered).c_str(),
      with_commas(s.queries_bad).c_str(), with_commas(s.queries_busy).c_str(), with_commas(s.queries_not_ready).c_str(),
      with_commas(s.queries_dropped).c_str(), with_commas(s.edits_applied).c_str(),
      with_commas(s.edits_refused).c_str(), with_commas(s.grids_published).c_str());
  const size_t n = std::min(s.query_refusal_reason.size(), s.query_refusal_count.size());
  if (n) {
    o << "    refused:";
    for (size_t i = 0; i < n; ++i)
      o << (i ? ", " : " ") << s.query_refusal_reason[i] << " " << with_commas(s.query_refusal_count[i]);
    o << "\n";
  }
  // The distance field cache: what the distance queries' fields and box replies cost.
  const int64_t fields = s.distance_fields_whole + s.distance_fields_partial + s.distance_fields_unchanged;
  if (fields > 0)
    o << fmt(
        "  distance  fields %s: %s whole, %s partial, %s unchanged (%s from change lists of %s cells, %s boxes "
        "read again); replies %s resent, frames %s of %s kept\n",
        with_commas(fields).c_str(), with_commas(s.distance_fields_whole).c_str(),
        with_commas(s.distance_fields_partial).c_str(), with_commas(s.distance_fields_unchanged).c_str(),
        with_commas(s.distance_patched).c_str(), with_commas(s.distance_patch_changes).c_str(),
        with_commas(s.distance_reread).c_str(), with_commas(s.distance_replies_kept).c_str(),
        with_commas(s.distance_frames_kept).c_str(), with_commas(s.distance_frames).c_str());
  if (s.query_clients.empty()) return;
  o << fmt("\n  %-16s %9s %9s %6s %7s %9s %7s %6s %10s  %s\n", "query client", "received", "answered", "bad", "busy",
           "not ready", "dropped", "queued", "last", "reply channel");
  for (const auto& c : s.query_clients)
    o << fmt("  %-16s %9s %9s %6s %7s %9s %7s %6d %10s  %s\n", c.client_id.c_str(), with_commas(c.received).c_str(),
             with_commas(c.answered).c_str(), with_commas(c.bad).c_str(), with_commas(c.busy).c_str(),
             with_commas(c.not_ready).c_str(), with_commas(c.dropped).c_str(), c.queue_depth,
             age_text(c.last_utime, now).c_str(), c.reply_channel.c_str());
}

}  // namespace

std::string state_name(int8_t state) {
  switch (state) {
    case Status::STATE_STARTING: return "STARTING";
    case Status::STATE_RUNNING: return "RUNNING";
    case Status::STATE_DEGRADED: return "DEGRADED";
    case Status::STATE_ERROR: return "ERROR";
    case Status::STATE_STOPPING: return "STOPPING";
  }
  return "STATE " + std::to_string(int(state));
}

std::string with_commas(int64_t v) {
  std::string digits = std::to_string(v < 0 ? -v : v), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return v < 0 ? "-" + out : out;
}

std::string bytes_text(int64_t bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  double v = double(bytes);
  int u = 0;
  while (std::abs(v) >= 1024 && u < 4) v /= 1024, ++u;
  return u == 0 ? fmt("%lld B", (long long)bytes) : fmt("%.1f %s", v, units[u]);
}

std::string duration_text(double seconds) {
  if (!(seconds >= 0)) return "?";
  if (seconds < 60) return fmt("%.0f s", seconds);
  const long long t = (long long)seconds;
  return t < 3600 ? fmt("%lld:%02lld", t / 60, t % 60) : fmt("%lld:%02lld:%02lld", t / 3600, t / 60 % 60, t % 60);
}

std::string rate_text(double v) {
  if (std::abs(v) >= 1e6) return fmt("%.2f M", v / 1e6);
  if (std::abs(v) >= 1e3) return fmt("%.1f k", v / 1e3);
  return fmt("%.1f", v);
}

std::string format_status(const Status& s, int64_t now_utime) {
  std::ostringstream o;
  header(o, s, now_utime);
  engine_and_map(o, s, now_utime);
  rates_and_latencies(o, s);
  queue_and_kernel(o, s);
  serving(o, s);
  robots(o, s, now_utime);
  o << "\n";
  queries(o, s, now_utime);
  return o.str();
}

}  // namespace ort::status
