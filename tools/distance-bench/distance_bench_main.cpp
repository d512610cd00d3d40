// octomap-rt-distance-bench: the daemon in this process over memq://, a real map streamed in,
// then distance queries timed from publish to the last reply message handled (the daemon's
// arrival-to-reply-sent plus memq's in-process hand-over), idle and while producers stream,
// the mapping throughput with box queries at a rate against none, and the same box computed
// without the daemon by octomap-rt's library and by OctoMap's DynamicEDTOctomap (the ratio of
// record, reference_timing.h). Every wait is bounded; scans the server refused or dropped are
// counted with their reasons.
//   octomap-rt-distance-bench [--graph G] [--producers 3] [--phase-s 10] ... [octomap-rt-server flags]
#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <random>
#include <thread>

#include <CLI/CLI.hpp>

#include "bench_replies.h"
#include "cli/replay/scan_message.h"
#include "core/clock.h"
#include "daemon/intake/reject_reason.h"
#include "daemon/mapping_server.h"
#include "daemon/server_cli.h"
#include "octomap_rt/distance_query_t.hpp"
#include "protocol/channels.h"
#include "reference_timing.h"
#include "reply_timing.h"
#include "scene/scan_set.h"

namespace {

using ort::seconds_since;
using ort::SteadyClock;
using ort::bench::LatencyStats;
using DQ = octomap_rt::distance_query_t;
const std::string kReply = "DISTANCE_BENCH_REPLY";

double since(SteadyClock::time_point t0) { return seconds_since(t0); }

// One robot's scans as the server counted them: every scan ends applied, rejected or dropped.
struct Tally {
  int64_t received = 0, applied = 0, rejected = 0, dropped = 0, in_flight = 0;
  std::string reasons;  // "origin jump 3, queue full 1"
  int64_t ended() const { return applied + rejected + dropped; }
};
// The registry names a robot by its channel's suffix as sent (upper case): compared without case.
bool same_robot(const std::string& a, const std::string& b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}
Tally tally(ort::daemon::MappingServer& s, const std::string& robot) {
  Tally t;
  for (const auto& p : s.producer_stats()) {
    if (!same_robot(p.robot_id, robot)) continue;
    t.received = p.received, t.applied = p.applied, t.rejected = p.rejected, t.dropped = p.dropped;
    t.in_flight = p.in_flight;
    for (size_t r = 0; r < ort::daemon::kRejectReasonCount; ++r) {
      const int64_t n = p.rejects[r] + p.drop_reasons[r];
      if (n > 0)
        t.reasons += (t.reasons.empty() ? "" : ", ") + std::string(ort::daemon::to_string(ort::daemon::Reject(r))) +
                     " " + std::to_string(n);
    }
  }
  return t;
}
int64_t applied_total(ort::daemon::MappingServer& s) {
  int64_t n = 0;
  for (const auto& p : s.producer_stats()) n += p.applied;
  return n;
}

void print_failures(const ort::bench::DistanceReplies& replies) {
  for (const auto& [why, n] : replies.failures()) std::printf("  not answered: %lld x %s\n", (long long)n, why.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"octomap-rt-distance-bench: distance queries against the daemon in one process"};
  std::string graph = "../shared/data/octomap_share/scan_dat.graph", csv;
  int producers = 3, points = 1000, box_queries = 20, point_queries = 50, reference_reps = 3, journal_phases = 0;
  double phase_s = 10, box_rate = 10, max_distance = 2.0, box_x = 20, box_y = 20, box_z = 3, wait_s = 300;
  double answer_timeout_s = 30;
  bool reference_vulkan = false;
  app.add_option("--graph", graph, "scans (ScanGraph) streamed in first and by the producers")->capture_default_str();
  app.add_option("--producers", producers, "producers streaming during the loaded phases")->capture_default_str();
  app.add_option("--phase-s", phase_s, "seconds of each streaming phase")->capture_default_str();
  app.add_option("--journal-phases", journal_phases,
                 "mapping phases before the first distance query (change journal unarmed) and after it")
      ->capture_default_str();
  app.add_option("--box-rate", box_rate, "box queries per second while streaming")->capture_default_str();
  app.add_option("--box-queries", box_queries, "box queries in the idle phase")->capture_default_str();
  app.add_option("--point-queries", point_queries, "point queries per phase")->capture_default_str();
  app.add_option("--points", points, "points per point query")->capture_default_str();
  app.add_option("--max-distance", max_distance, "[m]")->capture_default_str();
  app.add_option("--box-x", box_x, "box size [m]")->capture_default_str();
  app.add_option("--box-y", box_y)->capture_default_str();
  app.add_option("--box-z", box_z)->capture_default_str();
  app.add_option("--wait-s", wait_s, "longest wait for the preload's scans to be applied, refused or dropped")
      ->capture_default_str();
  app.add_option("--answer-timeout-s", answer_timeout_s, "longest wait for one query's answer")->capture_default_str();
  app.add_option("--reference-reps", reference_reps, "timed runs of the in-process reference (median)")
      ->capture_default_str();
  app.add_flag("--reference-vulkan", reference_vulkan, "also time the in-process box with the Vulkan EDT");
  app.add_option("--csv", csv, "append one line per phase");
  ort::daemon::ServerFlags flags;
  ort::daemon::add_server_flags(app, flags);
  CLI11_PARSE(app, argc, argv);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // a run cut by its caller's timeout keeps the lines it printed
  ort::daemon::ServerConfig cfg = ort::daemon::to_server_config(flags);
  cfg.save_interval_s = 0;
  cfg.map_path.clear();

  const ort::ScanSet scans = ort::load_scan_graph(graph);
  lcm::LCM lc("memq://");
  ort::daemon::MappingServer server(cfg, lc, std::cerr);
  ort::bench::DistanceReplies replies(server, kReply);
  server.start();
  const int64_t utime0 = ort::now_utime();
  // `shift` [m] moves the scan's pose (x, y): the exploring phase's robot maps space new to the box.
  auto publish_scan = [&](const std::string& robot, size_t i, int64_t s, double shift_x = 0, double shift_y = 0) {
    ort::cli::ScanMessageFields f;
    f.robot_id = robot, f.seq = s, f.utime = utime0 + s * 100'000;
    ort::PosedScan scan = scans.scans[i % scans.scans.size()];
    scan.pose.trans() += octomap::point3d(float(shift_x), float(shift_y), 0);
    const auto msg = ort::cli::make_scan_message(scan, f);
    lc.publish(ort::cli::scan_channel(ort::protocol::kScanChannelPrefix, robot), &msg);
  };
  // The field cache's counters since the last call (distance/field_cache.h): how its entry was
  // brought up to date (from the change lists or by reading the box again) and what that cost.
  ort::distance::FieldCacheStats cache_before;
  ort::daemon::ChangeJournalStats journal_before;
  auto cache_line = [&](const char* phase) {
    const ort::distance::FieldCacheStats c = server.distance_cache_stats();
    std::printf(
        "  field cache (%s): %lld from change lists (%lld cell changes), %lld box reads; %lld unchanged, %lld partial "
        "(%.0f cells each), %lld whole; %lld replies' bytes kept; of the replies made again, %lld of %lld z-slab "
        "frames kept\n",
        phase, (long long)(c.patched - cache_before.patched), (long long)(c.patch_changes - cache_before.patch_changes),
        (long long)(c.reread - cache_before.reread), (long long)(c.unchanged - cache_before.unchanged),
        (long long)(c.partial - cache_before.partial),
        c.partial > cache_before.partial
            ? double(c.partial_cells - cache_before.partial_cells) / double(c.partial - cache_before.partial)
            : 0.0,
        (long long)(c.full - cache_before.full), (long long)(c.replies_kept - cache_before.replies_kept),
        (long long)(c.frames_kept - cache_before.frames_kept), (long long)(c.frames - cache_before.frames));
    cache_before = c;
    // Stage 2's time in the journal (its applied(): the scans' class changes classified and kept).
    if (const auto j = server.change_journal_stats()) {
      const uint64_t n = j->scans - journal_before.scans;
      std::printf("  change journal (%s): %llu scans, %llu class changes, stage 2 in it %.1f us a scan\n", phase,
                  (unsigned long long)n, (unsigned long long)(j->changes - journal_before.changes),
                  n ? 1000.0 * (j->record_ms - journal_before.record_ms) / double(n) : 0.0);
      journal_before = *j;
    }
  };

  // Preload: at most 2 scans in flight; then wait until every scan ended (applied, refused or
  // dropped), within --wait-s.
  const auto preload_t0 = SteadyClock::now();
  for (size_t i = 0; i < scans.scans.size(); ++i) {
    while (tally(server, "map").in_flight > 2 && since(preload_t0) < wait_s)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    publish_scan("map", i, int64_t(i));
  }
  Tally pre = tally(server, "map");
  while (pre.ended() < int64_t(scans.scans.size()) && since(preload_t0) < wait_s) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    pre = tally(server, "map");
  }
  std::printf("preload: %zu scans sent, %lld received, %lld applied, %lld rejected, %lld dropped in %.1f s%s%s\n",
              scans.scans.size(), (long long)pre.received, (long long)pre.applied, (long long)pre.rejected,
              (long long)pre.dropped, since(preload_t0), pre.reasons.empty() ? "" : "; reasons: ", pre.reasons.c_str());
  if (pre.ended() < int64_t(scans.scans.size()))
    std::printf("preload: %lld scans not ended within --wait-s %g s (%lld in flight)\n",
                (long long)(int64_t(scans.scans.size()) - pre.ended()), wait_s, (long long)pre.in_flight);
  if (pre.applied == 0) {
    std::fprintf(stderr, "octomap-rt-distance-bench: no scan of %s was applied\n", graph.c_str());
    server.stop();
    return 1;
  }

  // The box: centred on the map's extent (x, y) and its floor (z).
  double lo[3], hi[3];
  server.with_map([&](const octomap::OcTree& t) {
    t.getMetricMin(lo[0], lo[1], lo[2]);
    t.getMetricMax(hi[0], hi[1], hi[2]);
    return 0;
  });
  const double size[3] = {box_x, box_y, box_z};
  double bmin[3], bmax[3];
  for (int a = 0; a < 3; ++a) {
    const double c = a == 2 ? lo[2] + size[2] / 2 : (lo[a] + hi[a]) / 2;
    bmin[a] = c - size[a] / 2, bmax[a] = c + size[a] / 2 - 1e-6;
  }
  std::printf("map: %lld scans of %s at %g m; box %g x %g x %g m from (%.2f, %.2f, %.2f), max %g m, EDT on %s\n",
              (long long)pre.applied, graph.c_str(), cfg.engine.resolution, box_x, box_y, box_z, bmin[0], bmin[1],
              bmin[2], max_distance, cfg.queries.distance.backend.c_str());

  // The same box without the daemon: octomap-rt's library and DynamicEDTOctomap.
  {
    ort::distance::DistanceOptions opt;
    opt.max_distance = max_distance;
    const ort::bench::ReferenceTimes r = server.with_map([&](const octomap::OcTree& t) {
      return ort::bench::time_reference(t, bmin, bmax, opt, cfg.queries.distance.threads, reference_reps,
                                        reference_vulkan);
    });
    std::printf("in-process box: %lld cells (%lld padded): read %.1f ms, CPU EDT (%d threads) %.1f ms",
                (long long)r.box_cells, (long long)r.padded_cells, r.read_ms, r.cpu_threads, r.cpu_edt_ms);
    if (r.vulkan_edt_ms >= 0) std::printf(", Vulkan EDT (%s) %.1f ms", r.vulkan_device.c_str(), r.vulkan_edt_ms);
    if (r.dynamic_edt_ms >= 0)
      std::printf("; DynamicEDTOctomap %.1f ms = %.1fx read + CPU EDT (%lld cells differ below the clamp)",
                  r.dynamic_edt_ms, r.dynamic_edt_ms / (r.read_ms + r.cpu_edt_ms), (long long)r.dynamic_edt_differ);
    else
      std::printf("; DynamicEDTOctomap not built in (libdynamicedt3d-dev)");
    if (r.dynamic_edt_differ > 0)
      std::printf(
          "\n  of those, ours = a brute-force search at %lld, DynamicEDTOctomap's the larger at %lld; "
          "(cell) ours theirs brute: %s",
          (long long)r.differ_ours_brute, (long long)r.differ_theirs_larger, r.differ_examples.c_str());
    std::printf("\n");
    const ort::bench::ReplyTimes rt = server.with_map([&](const octomap::OcTree& t) {
      return ort::bench::time_box_reply(t, bmin, bmax, opt, cfg.queries.distance.threads,
                                        cfg.queries.distance.zstd_level, reference_reps);
    });
    std::printf(
        "box reply stages (CPU EDT, %d threads, zstd %d): read %.1f ms; finish %.1f ms with the field computed "
        "whole, %.1f ms from the cache with the grid unchanged (the last reply's bytes kept; made again: box cut and "
        "clamped %.1f ms, bytes + zstd %.1f ms); blob %lld of %lld bytes in %lld chunks\n",
        cfg.queries.distance.threads, cfg.queries.distance.zstd_level, rt.read_ms, rt.whole_ms, rt.cached_ms,
        rt.clamp_ms, rt.zstd_ms, (long long)rt.blob_bytes, (long long)rt.raw_bytes, (long long)rt.chunks);
    std::printf("  zstd levels on the box's bytes:%s\n", rt.levels.c_str());
    std::printf(
        "  by z-slabs (%lld frames, %d threads, %lld bytes): cut, clamped and compressed %.2f ms (the two stages "
        "above take %.2fx that); again with the frames kept (%lld of them), cut and clamped %.2f ms\n",
        (long long)rt.slab_frames, cfg.queries.distance.threads, (long long)rt.slab_blob_bytes, rt.slabs_made_ms,
        rt.slabs_made_ms > 0 ? (rt.clamp_ms + rt.zstd_ms) / rt.slabs_made_ms : 0.0, (long long)rt.slab_frames_kept,
        rt.slabs_kept_ms);
  }

  std::mt19937 rng(27);
  int64_t next_id = 1;
  auto send = [&](DQ& q, const std::string& client) {
    q.request_id = next_id++, q.wait_seq = -1, q.client_id = client, q.reply_channel = kReply;
    q.max_distance = max_distance, q.cell_voxels = 1;
    const auto t = SteadyClock::now();
    lc.publish(ort::protocol::kQueryDistanceChannel, &q);
    return std::make_pair(q.request_id, t);
  };
  auto box_query = [&] {
    DQ q{};
    q.mode = DQ::MODE_BOX;
    std::copy(bmin, bmin + 3, q.box_min), std::copy(bmax, bmax + 3, q.box_max);
    return send(q, "bench");
  };
  auto point_query = [&] {
    DQ q{};
    q.mode = DQ::MODE_POINTS, q.with_gradient = 1;
    for (int p = 0; p < points; ++p)
      for (int a = 0; a < 3; ++a) q.xyz.push_back(float(std::uniform_real_distribution<double>(bmin[a], bmax[a])(rng)));
    q.num_xyz = int32_t(q.xyz.size());
    return send(q, "bench-points");
  };

  std::ofstream out;
  if (!csv.empty()) {
    const bool fresh = !std::ifstream(csv).good();
    out.open(csv, std::ios::app);
    if (fresh) out << "phase,queries,failed,p50_ms,p99_ms,max_ms,scans_per_s,producers,backend\n";
  }
  auto report = [&](const std::string& phase, const LatencyStats& s, double scans_per_s) {
    std::printf("%-18s queries %4zu  failed %3lld  p50 %8.2f ms  p99 %8.2f ms  max %8.2f ms  scans/s %7.1f\n",
                phase.c_str(), s.ms.size(), (long long)s.failed, s.pct(50), s.pct(99), s.pct(100), scans_per_s);
    if (out)
      out << phase << "," << s.ms.size() << "," << s.failed << "," << s.pct(50) << "," << s.pct(99) << "," << s.pct(100)
          << "," << scans_per_s << "," << producers << "," << cfg.queries.distance.backend << "\n";
    print_failures(replies);
  };

  // Streaming: producers keep 2 scans in flight each (as fast as the server maps), each going
  // round the scans in its own order; the phase lasts --phase-s whatever the queries do.
  // exploring: each scan's pose moved by a shift that grows with its seq (0.4 m, 0.25 m a scan,
  // wrapping within +-6 m): the map keeps growing into space the box had not seen.
  auto stream = [&](const std::function<void(const std::atomic<bool>&)>& queries, bool exploring = false) {
    std::atomic<bool> stop{false};
    std::vector<std::thread> threads;
    for (int p = 0; p < producers; ++p)
      threads.emplace_back([&, p] {
        const std::string robot = "bench" + std::to_string(p);
        int64_t s = 0;
        for (size_t i = size_t(p); !stop; i += size_t(producers)) {
          while (!stop && tally(server, robot).in_flight >= 2)
            std::this_thread::sleep_for(std::chrono::microseconds(500));
          const double sx = exploring ? std::fmod(0.4 * double(s), 12.0) - 6.0 : 0;
          const double sy = exploring ? std::fmod(0.25 * double(s) + 4.0 * p, 12.0) - 6.0 : 0;
          publish_scan(robot, i, s++, sx, sy);
        }
      });
    const int64_t before = applied_total(server);
    const auto t0 = SteadyClock::now();
    queries(stop);
    while (since(t0) < phase_s) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const double scans_per_s = double(applied_total(server) - before) / since(t0);
    stop = true;
    for (auto& t : threads) t.join();
    for (int p = 0; p < producers; ++p)
      if (const Tally t = tally(server, "bench" + std::to_string(p)); t.rejected + t.dropped > 0)
        std::printf("  bench%d: %lld rejected, %lld dropped: %s\n", p, (long long)t.rejected, (long long)t.dropped,
                    t.reasons.c_str());
    return scans_per_s;
  };
  // The change journal's cost on stage 2 (daemon/map/change_journal.h): mapping before any
  // distance query armed it, then after; and stage 2's own time in it (record_ms).
  double off_sum = 0, on_sum = 0;
  for (int i = 0; i < journal_phases; ++i) {
    const double r = stream([](const std::atomic<bool>&) {});
    off_sum += r;
    report("mapping unarmed", LatencyStats{}, r);
  }
  // Idle: one query at a time.
  LatencyStats idle_box, idle_points;
  for (int i = 0; i < box_queries; ++i) {
    const auto [id, t] = box_query();
    idle_box.add(replies.wait(id, t, answer_timeout_s));
  }
  report("box idle", idle_box, 0);
  cache_line("box idle");
  for (int i = 0; i < point_queries; ++i) {
    const auto [id, t] = point_query();
    idle_points.add(replies.wait(id, t, answer_timeout_s));
  }
  report("points idle", idle_points, 0);
  cache_line("points idle");
  auto journal_ms = [&] {
    const auto j = server.change_journal_stats();
    return j ? j->record_ms : 0.0;
  };
  const double record_before = journal_ms();
  const int64_t applied_before = applied_total(server);
  for (int i = 0; i < std::max(1, journal_phases); ++i) {
    const double r = stream([](const std::atomic<bool>&) {});
    on_sum += r;
    report("mapping alone", LatencyStats{}, r);
  }
  if (journal_phases > 0) {
    const int64_t n = applied_total(server) - applied_before;
    std::printf(
        "  change journal's cost: mapping %.1f scans/s armed = %.1f %% of %.1f unarmed (%d phases each); stage 2 in "
        "the journal's applied() %.1f us a scan (%.3f %% of the armed phases' time; the octree stage's leaf log not "
        "included)\n",
        on_sum / journal_phases, 100.0 * on_sum / off_sum, off_sum / journal_phases, journal_phases,
        n > 0 ? 1000.0 * (journal_ms() - record_before) / double(n) : 0.0,
        100.0 * (journal_ms() - record_before) / (1000.0 * phase_s * journal_phases));
  }
  // Boxes at --box-rate for the phase, then every reply waited for.
  auto boxes_at_rate = [&](LatencyStats& stats) {
    const auto t0 = SteadyClock::now();
    std::vector<std::pair<int64_t, SteadyClock::time_point>> sent;
    for (int i = 0; since(t0) < phase_s; ++i) {
      sent.push_back(box_query());
      std::this_thread::sleep_until(
          t0 + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>((i + 1) / box_rate)));
    }
    for (const auto& [id, t] : sent) stats.add(replies.wait(id, t, answer_timeout_s));
  };
  LatencyStats loaded_box;
  const double with_boxes = stream([&](const std::atomic<bool>&) { boxes_at_rate(loaded_box); });
  report("mapping + boxes", loaded_box, with_boxes);
  cache_line("mapping + boxes");
  LatencyStats loaded_points;
  const double with_points = stream([&](const std::atomic<bool>&) {
    for (int i = 0; i < point_queries; ++i) {
      const auto [id, t] = point_query();
      loaded_points.add(replies.wait(id, t, answer_timeout_s));
    }
  });
  report("mapping + points", loaded_points, with_points);
  cache_line("mapping + points");
  // A robot exploring: the producers' scans shifted into new space, boxes at --box-rate.
  LatencyStats exploring_box;
  const double exploring = stream([&](const std::atomic<bool>&) { boxes_at_rate(exploring_box); }, true);
  report("exploring + boxes", exploring_box, exploring);
  cache_line("exploring + boxes");
  if (const auto j = server.change_journal_stats())
    std::printf(
        "  change journal: %llu scans, %llu class changes recorded, %zu held, %llu trimmed; %llu asked, "
        "%llu could not say; stage 2 in it %.1f ms\n",
        (unsigned long long)j->scans, (unsigned long long)j->changes, j->held_changes, (unsigned long long)j->trimmed,
        (unsigned long long)j->answered, (unsigned long long)j->refused, j->record_ms);
  server.stop();
  return 0;
}
