// octomap-rt-server-bench: throughput of the server's two-stage pipeline against
// --no-pipeline, measured in one process on the same scans. Producers are threads that
// publish scan_t over memq:// into an in-process MappingServer (no network, so only the
// server's own work is timed: validation, to-map-frame, shoot, octree update).
//
//   octomap-rt-server-bench synthetic -r 0.1 --backend vulkan --producers 3 --repeat 4
//
// Prints scans/s and points/s for both modes, the ratio, and the overlap evidence.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <thread>

#include <CLI/CLI.hpp>

#include "cli/replay/scan_message.h"
#include "core/clock.h"
#include "daemon/mapping_server.h"
#include "engine/engine_flags.h"
#include "protocol/channels.h"
#include "scene/scan_set.h"
#include "scene/synthetic_scene.h"

namespace {

using namespace ort;

struct RunResult {
  double seconds = 0;
  int64_t scans = 0, points = 0;
  octomap_rt::server_status_t status;
};

// A producer's message of `scan` (the points in the sensor frame, as octomap-rt replay sends them).
octomap_rt::scan_t to_message(const PosedScan& scan, const std::string& robot, int64_t seq) {
  cli::ScanMessageFields f;
  f.robot_id = robot, f.seq = seq, f.utime = seq;
  return cli::make_scan_message(scan, f);
}

RunResult run(const daemon::ServerConfig& base, bool pipelined, const ScanSet& set, int producers, int repeat) {
  daemon::ServerConfig cfg = base;
  cfg.pipeline = pipelined;
  lcm::LCM lc("memq://");
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  server.start();
  // Messages are made before timing starts.
  std::vector<std::vector<octomap_rt::scan_t>> msgs(producers);
  for (int p = 0; p < producers; ++p)
    for (int r = 0; r < repeat; ++r)
      for (size_t k = p; k < set.scans.size(); k += producers)
        msgs[p].push_back(to_message(set.scans[k], "bench" + std::to_string(p), int64_t(msgs[p].size())));
  RunResult res;
  for (const auto& m : msgs) {
    res.scans += static_cast<int64_t>(m.size());
    for (const auto& s : m) res.points += s.num_xyz / 3;
  }
  const auto t0 = SteadyClock::now();
  std::vector<std::thread> threads;
  for (int p = 0; p < producers; ++p)
    threads.emplace_back([&, p] {
      for (const auto& m : msgs[p])
        lc.publish(std::string(ort::protocol::kScanChannelPrefix) + "BENCH" + std::to_string(p), &m);
    });
  for (auto& t : threads) t.join();
  for (;;) {
    int64_t done = 0;
    for (const auto& p : server.producer_stats()) done += p.applied + p.rejected + p.dropped;
    if (done >= res.scans) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  res.seconds = seconds_since(t0);
  res.status = server.status();
  server.stop();
  return res;
}

void print(const char* name, const RunResult& r) {
  const auto& s = r.status;
  std::printf(
      "  %-12s %7.2f s  %7.2f scans/s  %10.0f points/s  applied %lld/%lld  shoot p50 %.1f ms  octree p50 %.1f ms"
      "  busy: stage1 %.2f s, stage2 %.2f s, both %.2f s (%lld scans overlapped)\n",
      name, r.seconds, r.scans / r.seconds, r.points / r.seconds, (long long)s.scans_applied, (long long)r.scans,
      s.shoot_ms_p50, s.octree_ms_p50, s.stage1_busy_s, s.stage2_busy_s, s.overlap_busy_s,
      (long long)s.overlapped_scans);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"octomap-rt-server-bench: server pipeline vs --no-pipeline throughput, in-process over memq://"};
  std::string input;
  int producers = 3, repeat = 2;
  cli::EngineFlags flags;
  app.add_option("INPUT", input, "ScanGraph .graph file or 'synthetic'")->required();
  app.add_option("--producers", producers, "publishing threads, one robot each")->capture_default_str();
  app.add_option("--repeat", repeat, "publish the scan set this many times")->capture_default_str();
  cli::add_engine_flags(app, flags, /*require_resolution=*/true);
  CLI11_PARSE(app, argc, argv);
  try {
    daemon::ServerConfig cfg;
    cfg.engine = cli::to_engine_options(flags);
    cfg.save_interval_s = 0;
    cfg.queue_budget_bytes = 4ull << 30;  // measure throughput, not the drop policy
    const ScanSet set = input == "synthetic" ? make_synthetic_rooms() : load_scan_graph(input);
    std::printf("octomap-rt-server-bench: %s, %zu scans x %d, %d producers, resolution %g\n", set.name.c_str(),
                set.scans.size(), repeat, producers, cfg.engine.resolution);
    const RunResult seq = run(cfg, false, set, producers, repeat);
    const RunResult pipe = run(cfg, true, set, producers, repeat);
    std::printf("  back end %s on %s\n", pipe.status.backend.c_str(), pipe.status.device.c_str());
    print("no-pipeline", seq);
    print("pipeline", pipe);
    std::printf("  pipeline speed-up: %.2fx scans/s\n", (pipe.scans / pipe.seconds) / (seq.scans / seq.seconds));
  } catch (const std::exception& e) {
    std::cerr << "octomap-rt-server-bench: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
