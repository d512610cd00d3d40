#include "daemon/status/run_summary.h"

#include <cstdio>

namespace ort::daemon {
namespace {

void print_producers(std::ostream& out, const StatusInputs& s) {
  char line[512];
  out << "  producers (received = applied + rejected + dropped):\n";
  for (const ProducerStats& p : s.producers) {
    std::snprintf(line, sizeof line,
                  "    %-16s received %lld = applied %lld + rejected %lld + dropped %lld%s; missed (seq gaps) %lld; "
                  "seq restarts %lld; points %lld\n",
                  p.robot_id.c_str(), (long long)p.received, (long long)p.applied, (long long)p.rejected,
                  (long long)p.dropped, p.in_flight ? (" + in flight " + std::to_string(p.in_flight)).c_str() : "",
                  (long long)p.missed, (long long)p.seq_restarts, (long long)p.points_applied);
    out << line;
    std::string reasons;
    for (size_t k = 0; k < kRejectReasonCount; ++k)
      if (p.rejects[k])
        reasons += std::string(reasons.empty() ? "" : ", ") + to_string(static_cast<Reject>(k)) + " " +
                   std::to_string(p.rejects[k]);
    if (!reasons.empty()) out << "      rejected: " << reasons << "\n";
    std::string drops;
    for (size_t k = 0; k < kRejectReasonCount; ++k)
      if (p.drop_reasons[k])
        drops += std::string(drops.empty() ? "" : ", ") + to_string(static_cast<Reject>(k)) + " " +
                 std::to_string(p.drop_reasons[k]);
    if (!drops.empty()) out << "      dropped: " << drops << "\n";
    std::string points;
    for (size_t k = 0; k < kPointDropReasonCount; ++k)
      if (p.point_drops[k])
        points += std::string(points.empty() ? "" : ", ") + to_string(static_cast<PointDrop>(k)) + " " +
                  std::to_string(p.point_drops[k]);
    if (!points.empty()) out << "      points without a ray: " << points << "\n";
  }
}

void print_stages(std::ostream& out, const MetricsSnapshot& m) {
  char line[512];
  std::snprintf(line, sizeof line,
                "  stage times:  shoot (stage 1) p50 %.2f ms p99 %.2f ms, total %.1f ms; octree (stage 2) p50 %.2f ms "
                "p99 %.2f ms, total %.1f ms; end to end p50 %.2f ms p99 %.2f ms\n",
                m.shoot_p50, m.shoot_p99, m.shoot_total_ms, m.octree_p50, m.octree_p99, m.octree_total_ms, m.e2e_p50,
                m.e2e_p99);
  out << line;
  const StageTimes& p = m.stage1_total;
  const double n = m.scans_applied ? double(m.scans_applied) : 1.0;
  std::snprintf(line, sizeof line,
                "  stage 1 parts (ms a scan, mean): upload %.3f, prepare %.3f, shoot %.3f (device %.3f), compact "
                "%.3f (device %.3f, copy %.3f, unpack %.3f), rest %.3f\n",
                p.upload_ms / n, p.prepare_ms / n, p.shoot_ms / n, p.shoot_gpu_ms / n, p.compact_ms / n,
                p.compact_gpu_ms / n, p.readback_copy_ms / n, p.unpack_ms / n,
                (m.shoot_total_ms - p.upload_ms - p.prepare_ms - p.shoot_ms - p.compact_ms) / n);
  out << line;
  std::snprintf(line, sizeof line,
                "  waits:        decode (LCM thread) p50 %.2f ms p99 %.2f ms; queue p50 %.2f ms p99 %.2f ms; hand-off "
                "to stage 2 p50 %.2f ms p99 %.2f ms\n",
                m.decode.p50, m.decode.p99, m.queue_wait.p50, m.queue_wait.p99, m.handoff_wait.p50, m.handoff_wait.p99);
  out << line;
  std::snprintf(line, sizeof line,
                "  overlap:      stage 1 busy %.3f s, stage 2 busy %.3f s, both at once %.3f s; %lld of %lld scans "
                "had their octree update overlap another scan's shoot\n",
                m.overlap.busy_s[0], m.overlap.busy_s[1], m.overlap.both_s, (long long)m.overlapped_scans,
                (long long)m.scans_applied);
  out << line;
}

// One line a scan: its end-to-end time split into the parts that add up to it.
void print_slowest(std::ostream& out, const MetricsSnapshot& m) {
  if (m.slowest.empty()) return;
  out << "  slowest scans (end to end = decode + queue + stage 1 + hand-off + stage 2; of all " << m.scans_applied
      << " applied):\n";
  char line[768];
  for (const SlowScan& s : m.slowest) {
    const AppliedTiming& t = s.timing;
    const StageTimes& p = t.stage1;
    std::snprintf(line, sizeof line,
                  "    #%lld %s seq %lld at +%.3f s: %.2f ms = decode %.2f + queue %.2f + stage 1 %.2f (upload %.2f, "
                  "prepare %.2f, shoot %.2f, compact %.2f) + hand-off %.2f + stage 2 %.2f (lock wait %.2f, octree "
                  "%.2f, deltas %.2f); %llu voxels, %lld new nodes\n",
                  (long long)s.applied_index, t.robot_id.c_str(), (long long)t.seq, s.received_s, t.end_to_end_ms,
                  t.waits.decode_ms, t.waits.queue_ms, t.shoot_ms, p.upload_ms, p.prepare_ms, p.shoot_ms, p.compact_ms,
                  t.waits.handoff_ms, t.octree_ms, t.stage2.lock_wait_ms, t.stage2.update_ms, t.stage2.publish_ms,
                  (unsigned long long)t.voxels, (long long)t.new_nodes);
    out << line;
  }
}

void print_files(std::ostream& out, const RunSummaryInputs& in) {
  const StatusInputs& s = in.status;
  char line[1024];
  if (!s.map_path.empty()) {
    std::snprintf(line, sizeof line,
                  "  map file:     %s (saved %lld times; last save %.1f ms, map lock held at most %.1f ms)\n"
                  "  order file:   %s.order\n",
                  s.map_path.c_str(), (long long)s.map_saves, in.last_save_ms, in.max_save_lock_ms, s.map_path.c_str());
    out << line;
  } else {
    out << "  map file:     none (no --map given: the map was not saved)\n";
  }
  if (!in.final_save_error.empty())
    out << "  FINAL SAVE FAILED: " << in.final_save_error << " (the map file holds the last successful save)\n";
  if (!in.applied_log.empty()) out << "  applied log:  " << in.applied_log << "\n";
}

void print_serving(std::ostream& out, const RunSummaryInputs& in) {
  const MapServiceStats& m = in.map_service;
  char line[512];
  std::snprintf(line, sizeof line,
                "  snapshots:    %lld taken, %lld requests served (%lld chunks), %lld refused or ignored",
                (long long)m.snapshots_taken, (long long)m.requests_served, (long long)m.chunks_sent,
                (long long)m.requests_rejected);
  out << line;
  std::string reasons;
  for (size_t k = 1; k < protocol::kRequestRefusalCount; ++k)
    if (m.refusals[k])
      reasons += std::string(reasons.empty() ? "" : ", ") + to_string(static_cast<protocol::RequestRefusal>(k)) + " " +
                 std::to_string(m.refusals[k]);
  out << (reasons.empty() ? "" : " (" + reasons + ")") << "\n";
  if (m.snapshots_taken > 0) {
    std::snprintf(line, sizeof line,
                  "                last: %lld bytes raw, %lld compressed; copy held the map lock %.1f ms (at most "
                  "%.1f ms), serialize %.1f ms, compress %.1f ms\n",
                  (long long)m.last_raw_size, (long long)m.last_size, m.last_copy_lock_ms, m.max_copy_lock_ms,
                  m.last_serialize_ms, m.last_compress_ms);
    out << line;
  }
  const DeltaStats& d = in.deltas;
  if (!in.deltas_on) {
    out << "  deltas:       off\n";
    return;
  }
  std::snprintf(line, sizeof line,
                "  deltas:       %lld messages in %lld change sets for %lld scans, %lld voxels, %lld bytes (%.0f "
                "bytes a scan)\n",
                (long long)d.messages, (long long)d.sets, (long long)d.scans, (long long)d.voxels, (long long)d.bytes,
                d.scans ? double(d.bytes) / double(d.scans) : 0.0);
  out << line;
}

}  // namespace

void print_run_summary(std::ostream& out, const RunSummaryInputs& in) {
  const StatusInputs& s = in.status;
  char line[512];
  out << "octomap-rt-server summary\n";
  std::snprintf(line, sizeof line, "  ran %.1f s as %s; back end %s on %s; pipeline %s; resolution %g m\n", s.uptime_s,
                s.server_id.c_str(), s.backend.c_str(), s.device.c_str(), s.pipelined ? "on" : "off", s.resolution);
  out << line;
  print_producers(out, s);
  print_stages(out, s.metrics);
  print_slowest(out, s.metrics);
  std::snprintf(line, sizeof line,
                "  map:          %lld nodes (%lld leaves), %.1f MiB in memory, %zu scans applied in total\n",
                (long long)s.num_nodes, (long long)s.num_leaf_nodes, s.memory_bytes / 1048576.0, in.scans_in_map);
  out << line;
  out << "  kernel UDP drops: " << s.socket_rcvbuf_drops << " on the server's sockets, " << s.kernel_rcvbuf_errors
      << " in this network namespace (all programs; -1: unknown)\n";
  if (s.lcm_handler_errors > 0)
    out << "  LCM handler errors: " << s.lcm_handler_errors << " messages (each logged as it happened)\n";
  if (s.map_memory_bound > 0) {
    std::snprintf(line, sizeof line,
                  "  memory bound: %.1f MiB; %lld regions evicted (%.1f MiB in the store), %lld evictions, %lld "
                  "restores, %lld refused by the store; RSS %.1f MiB; %lld passes %.0f ms (exact counts %.0f, "
                  "longest %.1f), restores %.0f ms (longest %.1f a scan)\n",
                  s.map_memory_bound / 1048576.0, (long long)s.evicted_regions, s.evicted_bytes / 1048576.0,
                  (long long)s.region_evictions, (long long)s.region_restores, (long long)s.region_store_failures,
                  s.rss_bytes / 1048576.0, (long long)s.evict_passes, s.evict_ms, s.evict_count_ms, s.evict_ms_max,
                  s.restore_ms, s.restore_ms_max);
    out << line;
  }
  print_serving(out, in);
  print_files(out, in);
}

}  // namespace ort::daemon
