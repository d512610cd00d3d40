// octomap-rt-bigmap-bench: whole-map readers against a big map (issue 23), in one process
// over memq:// (the server's own work only: no network).
//
//   octomap-rt-bigmap-bench grow --preset campus -r 0.1 --target-nodes 5000000 --map big.ot
//   octomap-rt-bigmap-bench run --map big.ot -r 0.1 --readers on --duration 60
//
// `grow` feeds the preset's scans one at a time until the map has --target-nodes nodes and
// saves it. `run` starts a fresh server on a copy of that map and streams the preset's scans
// from --producers robots at --rate each for --duration seconds, with the readers on (a fresh
// snapshot pulled every --snapshot-period, autosave every --save-interval, the viewer
// publisher at --octomap-raw-rate, --query-rate point queries a second) or off, then prints
// the octree stage's lock waits (the stall readers caused), scans' end-to-end p50/p99,
// queries' p50/p99, snapshot fetch times and the process's memory. docs/BENCHMARKS.md.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <thread>

#include <CLI/CLI.hpp>

#include "bigmap_readers.h"
#include "cli/replay/scan_message.h"
#include "core/clock.h"
#include "daemon/mapping_server.h"
#include "engine/engine_flags.h"
#include "protocol/channels.h"
#include "scene/scan_set.h"
#include "scene/scene_presets.h"

namespace {

using namespace ort;

// A producer's message of `scan` (the points in the sensor frame, as octomap-rt replay sends them).
octomap_rt::scan_t to_message(const PosedScan& scan, const std::string& robot, int64_t seq) {
  cli::ScanMessageFields f;
  f.robot_id = robot, f.seq = seq, f.utime = seq + 1;
  return cli::make_scan_message(scan, f);
}

int64_t finished(daemon::MappingServer& s) {
  int64_t done = 0;
  for (const auto& p : s.producer_stats()) done += p.applied + p.rejected + p.dropped;
  return done;
}

double rss_mib(const char* key) {
  FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return -1;
  char line[256];
  double kib = -1;
  while (std::fgets(line, sizeof line, f))
    if (std::strncmp(line, key, std::strlen(key)) == 0) kib = std::atof(line + std::strlen(key));
  std::fclose(f);
  return kib / 1024.0;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())))];
}

struct Args {
  std::string preset = "campus", map;
  double scan_scale = 1.0, point_scale = 0.25, stream_point_scale = 0.05;
  int64_t target_nodes = 5'000'000;
  int producers = 3;
  double rate = 1.0, duration = 60, drain_timeout = 300;
  std::string readers = "on", replica = "on";
  uint64_t replica_batch_voxels = daemon::MapReplica::kDefaultBatchVoxels;
  uint64_t replica_pending_bytes = daemon::ServerConfig{}.replica_pending_bytes;
  int replica_nice = 10;
  double replica_batch_ms = 0;
  uint64_t replica_rebuild_slice_nodes = 0;
  std::string replica_versions = "on";
  unsigned replica_version_depth = 0;
  std::string replica_version_writes = "cells";
  unsigned replica_threads = 0;
  double snapshot_period = 1, save_interval = 10, raw_rate = 1, query_rate = 100;
  int query_clients = 1;
  cli::EngineFlags engine;
};

daemon::ServerConfig server_config(const Args& a) {
  daemon::ServerConfig cfg;
  cfg.engine = cli::to_engine_options(a.engine);
  cfg.queue_budget_bytes = 1ull << 30;
  cfg.warm_up_points = 0;
  cfg.serving.chunk_interval_ms = 0.2;
  cfg.latency_bound_s = 60;
  cfg.read_replica = a.replica == "on";
  cfg.replica_batch_voxels = a.replica_batch_voxels;
  cfg.replica_pending_bytes = a.replica_pending_bytes;
  cfg.replica_nice = a.replica_nice;
  cfg.replica_batch_ms = a.replica_batch_ms;
  cfg.replica_rebuild_slice_nodes = a.replica_rebuild_slice_nodes;
  cfg.replica_versions = a.replica_versions == "on";
  cfg.replica_version_depth = a.replica_version_depth;
  cfg.replica_version_cells = a.replica_version_writes == "cells";
  cfg.replica_threads = a.replica_threads;
  // The producers go round the preset's scans (origins far apart, many new nodes a second at
  // the GPU machine's rates): the per-producer cost gates would refuse the scans it measures.
  cfg.scan_costs.max_origin_jump_m = 0;
  cfg.scan_costs.max_new_nodes_per_s = 0;
  cfg.scan_costs.max_map_new_nodes_per_s = 0;
  return cfg;
}

int grow(const Args& a) {
  PresetOptions po;
  po.scan_scale = a.scan_scale;
  po.point_scale = a.point_scale;
  const ScanSet set = make_preset(a.preset, po);
  daemon::ServerConfig cfg = server_config(a);
  cfg.map_path = a.map;
  cfg.save_interval_s = 0;
  std::filesystem::remove(a.map);
  lcm::LCM lc("memq://");
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  server.start();
  const auto t0 = SteadyClock::now();
  int64_t seq = 0, nodes = 0;
  while (nodes < a.target_nodes && seq < 100'000) {
    const auto m = to_message(set.scans[static_cast<size_t>(seq) % set.scans.size()], "grow", seq);
    lc.publish(std::string(protocol::kScanChannelPrefix) + "GROW", &m);
    ++seq;
    while (finished(server) < seq) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    nodes = server.status().num_nodes;
    std::printf("grow: scan %lld, %lld nodes, %.0f s\n", (long long)seq, (long long)nodes, seconds_since(t0));
    std::fflush(stdout);
    if (static_cast<size_t>(seq) == set.scans.size() && nodes < a.target_nodes)
      std::printf("grow: every scan applied once; going round again (more scans: --scan-scale)\n");
  }
  server.stop();
  std::printf("grow: saved %s: %lld nodes after %lld scans (%s)\n", a.map.c_str(), (long long)nodes, (long long)seq,
              set.name.c_str());
  return nodes >= a.target_nodes ? 0 : 1;
}

int run(const Args& a) {
  const bool readers = a.readers == "on";
  PresetOptions po;
  po.scan_scale = a.scan_scale;
  po.point_scale = a.stream_point_scale;
  const ScanSet set = make_preset(a.preset, po);
  const std::string dir = std::filesystem::temp_directory_path() / ("bigmap-bench-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  daemon::ServerConfig cfg = server_config(a);
  cfg.map_path = dir + "/map.ot";
  std::filesystem::copy_file(a.map, cfg.map_path);
  cfg.save_interval_s = readers ? a.save_interval : 0;
  cfg.octomap_raw.rate_hz = readers ? a.raw_rate : 0;
  const double rss_before = rss_mib("VmRSS:");
  lcm::LCM lc("memq://");
  std::ostringstream log;
  const auto load0 = SteadyClock::now();
  daemon::MappingServer server(cfg, lc, log);
  const double load_s = seconds_since(load0);
  const auto loaded = server.status();
  const double rss_loaded = rss_mib("VmRSS:");
  // Progress on stderr (unbuffered): a run cut off by its caller still says how far it got.
  std::fprintf(stderr, "run: map loaded, %lld nodes in %.1f s\n", (long long)loaded.num_nodes, load_s);
  // Queries go where the map is: its bounding box.
  double lo[3], hi[3];
  server.with_map([&](const octomap::OcTree& t) {
    t.getMetricMin(lo[0], lo[1], lo[2]);
    t.getMetricMax(hi[0], hi[1], hi[2]);
    return 0;
  });
  bench::BenchReaders r(server, lc, readers ? a.snapshot_period : 0, readers ? a.query_rate : 0, a.query_clients, lo,
                        hi);
  server.start();
  r.start();
  std::vector<octomap_rt::scan_t> msgs;
  for (size_t k = 0; k < set.scans.size(); ++k) msgs.push_back(to_message(set.scans[k], "p", 0));
  std::vector<std::thread> producers;
  std::atomic<int64_t> published{0};
  const auto t0 = SteadyClock::now();
  for (int p = 0; p < a.producers; ++p)
    producers.emplace_back([&, p] {
      const std::string robot = "bench" + std::to_string(p);
      const std::string channel = std::string(protocol::kScanChannelPrefix) + "BENCH" + std::to_string(p);
      const auto period = std::chrono::duration<double>(1.0 / a.rate);
      auto next = t0 + std::chrono::duration_cast<SteadyClock::duration>(period * p / a.producers);
      for (int64_t seq = 0; SteadyClock::now() - t0 < std::chrono::duration<double>(a.duration); ++seq) {
        std::this_thread::sleep_until(next);
        octomap_rt::scan_t m = msgs[static_cast<size_t>(seq * a.producers + p) % msgs.size()];
        m.robot_id = robot;
        m.seq = seq;
        m.utime = seq + 1;
        lc.publish(channel, &m);
        published++;
        next += std::chrono::duration_cast<SteadyClock::duration>(period);
      }
    });
  for (auto& t : producers) t.join();
  std::fprintf(stderr, "run: %lld scans published in %.1f s, %lld finished; waiting for the rest (at most %.0f s)\n",
               (long long)published.load(), seconds_since(t0), (long long)finished(server), a.drain_timeout);
  const auto drain_end = SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                                                  std::chrono::duration<double>(a.drain_timeout));
  while (finished(server) < published && SteadyClock::now() < drain_end)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const double seconds = seconds_since(t0);
  r.stop();
  const auto st = server.status();
  const daemon::MetricsSnapshot metrics = server.pipeline_metrics();
  const auto holders = server.map_lock_holders();
  const auto replica_holders = server.replica_lock_holders();
  const double rss_end = rss_mib("VmRSS:"), hwm = rss_mib("VmHWM:");
  const bench::ReaderStats rs = r.stats();
  server.stop();
  const auto replica = server.replica_stats();
  std::filesystem::remove_all(dir);
  std::printf(
      "bigmap: readers %s (read replica %s, versions %s), map %lld nodes (loaded in %.1f s), %lld scans applied of %lld in %.1f s (%d producers x "
      "%.2f Hz, %s at point scale %g), backend %s\n",
      readers ? "on" : "off", a.replica.c_str(), a.replica_versions.c_str(), (long long)loaded.num_nodes, load_s,
      (long long)st.scans_applied, (long long)published.load(), seconds, a.producers, a.rate, a.preset.c_str(),
      a.stream_point_scale, st.backend.c_str());
  std::printf("  octree stage: lock wait max %.1f ms (waited for: %s), p99 %.2f ms; octree p50 %.1f ms p99 %.1f ms\n",
              st.octree_lock_wait_ms_max, metrics.lock_wait_max_holder, st.octree_lock_wait_ms_p99, st.octree_ms_p50,
              st.octree_ms_p99);
  auto print_holders = [](const char* what, const std::vector<daemon::LockHolderFigures>& hs) {
    std::printf("  %s lock held by (longest first):", what);
    for (const auto& h : hs)
      std::printf(" %s: %llu holds, max %.1f ms, %.0f ms in all;", h.name, (unsigned long long)h.holds, h.max_ms,
                  h.total_ms);
    std::printf("\n");
  };
  print_holders("map of record's", holders);
  if (!replica_holders.empty()) print_holders("read replica's", replica_holders);
  std::printf("  scans end to end: p50 %.1f ms, p99 %.1f ms\n", st.end_to_end_ms_p50, st.end_to_end_ms_p99);
  std::printf(
      "  queries (%d clients): %lld sent, %zu answered, p50 %.2f ms, p99 %.2f ms, %lld unanswered, "
      "%lld answered not OK\n",
      readers ? a.query_clients : 0, (long long)rs.queries_sent, rs.query_ms.size(), percentile(rs.query_ms, 0.5),
      percentile(rs.query_ms, 0.99), (long long)rs.queries_unanswered, (long long)rs.queries_not_ok);
  std::printf("  snapshots: %lld fetched (%lld timed out), mean %.2f s, max %.2f s, %.1f MB; saves %lld\n",
              (long long)rs.snapshots, (long long)rs.snapshot_timeouts,
              rs.snapshots ? rs.snapshot_s_sum / double(rs.snapshots) : 0.0, rs.snapshot_s_max,
              double(rs.snapshot_bytes) / 1e6, (long long)st.map_saves);
  if (!rs.snapshot_error.empty()) std::printf("  snapshot refused: %s\n", rs.snapshot_error.c_str());
  if (replica)
    std::printf(
        "  read replica: %.1f s of updates on its thread (%llu updates, %llu scans in batches, at most %llu in one), "
        "at most %.1f MB pending, stage 2 waited %.1f ms for room, fell behind %llu times (%llu changes dropped; %llu rebuilds caught up, %llu "
        "slices holding the map of record %.1f ms in all, at most %.1f ms); its thread waited %.1f s for readers (at "
        "most %.1f ms); %llu batches cut at --replica-batch-ms %.1f (estimate %.2f us a voxel)\n",
        replica->apply_ms_total / 1e3, (unsigned long long)replica->updates,
        (unsigned long long)replica->scans_in_batches, (unsigned long long)replica->largest_batch,
        double(replica->max_pending_bytes_seen) / 1e6, replica->writer_waited_ms,
        (unsigned long long)replica->fell_behind, (unsigned long long)replica->dropped_items,
        (unsigned long long)replica->rebuilds_done, (unsigned long long)replica->rebuild_slices,
        replica->rebuild_hold_ms_total, replica->rebuild_hold_ms_max, replica->lock_wait_ms_total / 1e3,
        replica->lock_wait_ms_max, (unsigned long long)replica->batches_cut_by_time, a.replica_batch_ms,
        1e3 * replica->ms_per_voxel);
  if (replica)
    std::printf("  read replica's thread: %.1f s idle, %.1f s noting changes for versions after its updates\n",
                replica->idle_ms_total / 1e3, replica->version_note_ms_total / 1e3);
  if (replica && replica->fell_behind > 0)
    std::printf("  read replica fell behind: %s\n", replica->behind_reason.c_str());
  if (replica && replica->versions_built > 0)
    std::printf(
        "  versions for whole-map readers: %llu made on the replica's thread, %.1f s in all, at most %.1f ms; the "
        "last wrote %llu of its %llu regions (depth %u, %s), %.1f of %.1f MB; those after the first: %.1f s, "
        "%.1f s of CPU, %.1f MB written (%.0f %% of its nodes copied from old records)\n",
        (unsigned long long)replica->versions_built, replica->version_ms_total / 1e3, replica->version_ms_max,
        (unsigned long long)replica->version_regions_written, (unsigned long long)replica->version_regions,
        replica->version_depth, a.replica_version_writes.c_str(), double(replica->version_bytes_written) / 1e6,
        double(replica->version_bytes) / 1e6, replica->version_ms_later / 1e3, replica->version_cpu_ms_later / 1e3,
        double(replica->version_bytes_written_later) / 1e6,
        replica->version_nodes_written_later
            ? 100.0 * double(replica->version_nodes_copied_later) / double(replica->version_nodes_written_later)
            : 0.0);
  std::printf("  memory: RSS %.0f MiB before the map, %.0f MiB loaded, %.0f MiB at the end, peak %.0f MiB\n",
              rss_before, rss_loaded, rss_end, hwm);
  // readers, replica, nodes, scans, s, stall max, stall p99, e2e p50, e2e p99, query p50, query p99, snapshots,
  // snapshot max s, RSS loaded, RSS peak, replica update s, replica batch voxels, replica nice, query clients,
  // stage 2's wait for the replica's room [ms], the times the replica fell behind, --replica-rebuild-slice-nodes
  std::printf(
      "csv,%s,%s,%lld,%lld,%.1f,%.3f,%.3f,%.2f,%.2f,%.2f,%.2f,%lld,%.2f,%.0f,%.0f,%.1f,%llu,%d,%d,%.1f,%llu,%llu\n",
      readers ? "on" : "off", a.replica.c_str(), (long long)loaded.num_nodes, (long long)st.scans_applied, seconds,
      st.octree_lock_wait_ms_max, st.octree_lock_wait_ms_p99, st.end_to_end_ms_p50, st.end_to_end_ms_p99,
      percentile(rs.query_ms, 0.5), percentile(rs.query_ms, 0.99), (long long)rs.snapshots, rs.snapshot_s_max,
      rss_loaded, hwm, replica ? replica->apply_ms_total / 1e3 : 0.0, (unsigned long long)a.replica_batch_voxels,
      a.replica_nice, readers ? a.query_clients : 0, replica ? replica->writer_waited_ms : 0.0,
      replica ? (unsigned long long)replica->fell_behind : 0ull, (unsigned long long)a.replica_rebuild_slice_nodes);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"octomap-rt-bigmap-bench: whole-map readers against a big map, in-process over memq://"};
  app.require_subcommand(1);
  Args a;
  auto common = [&](CLI::App* c) {
    c->add_option("--preset", a.preset, "scan preset (octomap-rt scenegen's)")->capture_default_str();
    c->add_option("--scan-scale", a.scan_scale, "share of the preset's scans")->capture_default_str();
    c->add_option("--map", a.map, "the big map (.ot): written by grow, read by run")->required();
    cli::add_engine_flags(*c, a.engine, /*require_resolution=*/true);
  };
  CLI::App* g = app.add_subcommand("grow", "grow a map to --target-nodes and save it");
  common(g);
  g->add_option("--point-scale", a.point_scale, "share of each scan's points")->capture_default_str();
  g->add_option("--target-nodes", a.target_nodes, "octree nodes to reach")->capture_default_str();
  CLI::App* r = app.add_subcommand("run", "serve the map to streaming producers, readers on or off");
  common(r);
  r->add_option("--stream-point-scale", a.stream_point_scale, "share of each streamed scan's points")
      ->capture_default_str();
  r->add_option("--producers", a.producers, "streaming robots")->capture_default_str();
  r->add_option("--rate", a.rate, "scans a second per robot")->capture_default_str();
  r->add_option("--duration", a.duration, "seconds of streaming")->capture_default_str();
  r->add_option("--drain-timeout", a.drain_timeout,
                "after streaming, wait at most this long [s] for the scans still queued (the rest count as not "
                "applied)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  r->add_option("--readers", a.readers, "on: snapshots, autosave, viewer publisher, queries; off: none")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  r->add_option("--read-replica", a.replica, "on: readers read the server's read replica; off: the map of record")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  r->add_option("--replica-batch-voxels", a.replica_batch_voxels,
                "scans waiting for the read replica are applied together up to this many voxels (0: one by one)")
      ->capture_default_str();
  r->add_option("--replica-rebuild-slice-nodes", a.replica_rebuild_slice_nodes,
                "> 0: past --replica-pending-bytes the replica falls behind and rebuilds from the map of record in "
                "slices of at most this many nodes (stage 2 never waits); 0: stage 2 waits for its room")
      ->capture_default_str();
  r->add_option("--replica-batch-ms", a.replica_batch_ms,
                "... and only while the update's estimated time stays within this [ms] (0: no time bound)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  r->add_option("--replica-pending-bytes", a.replica_pending_bytes,
                "how far (bytes of changes) the read replica may lag before stage 2 waits for it")
      ->capture_default_str();
  r->add_option("--replica-threads", a.replica_threads, "the read replica's octree threads (0: every hardware thread)")
      ->capture_default_str();
  r->add_option("--replica-nice", a.replica_nice, "how much the read replica's thread lowers its priority (nice)")
      ->capture_default_str();
  r->add_option("--replica-versions", a.replica_versions,
                "on: snapshots, saves and the viewer map read versions of the read replica (no lock); off: they "
                "copy it under its lock")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  r->add_option("--replica-version-depth", a.replica_version_depth,
                "the depth of the regions the read replica's versions are kept in (0: the eviction's)")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  r->add_option("--replica-version-writes", a.replica_version_writes,
                "cells: a version writes the cells where the replica changed a leaf; regions: it rewrites every "
                "region the scans' keys touched, whole (the design before)")
      ->check(CLI::IsMember({"cells", "regions"}))
      ->capture_default_str();
  r->add_option("--snapshot-period", a.snapshot_period, "a fresh snapshot pulled this often [s]")
      ->capture_default_str();
  r->add_option("--save-interval", a.save_interval, "autosave period [s]")->capture_default_str();
  r->add_option("--octomap-raw-rate", a.raw_rate, "viewer publisher rate [Hz]")->capture_default_str();
  r->add_option("--query-rate", a.query_rate, "point queries a second")->capture_default_str();
  r->add_option("--query-clients", a.query_clients, "query clients (own client ids) sharing --query-rate")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    return g->parsed() ? grow(a) : run(a);
  } catch (const std::exception& e) {
    std::cerr << "octomap-rt-bigmap-bench: error: " << e.what() << "\n";
    return 1;
  }
}
