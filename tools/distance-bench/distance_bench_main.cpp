// octomap-rt-distance-bench: the daemon in this process over memq://, a real map streamed in,
// then distance queries timed from publish to the last reply message handled (the daemon's
// arrival-to-reply-sent plus memq's in-process hand-over), idle and while producers stream,
// and the mapping throughput with box queries at a rate against none.
//   octomap-rt-distance-bench [--graph G] [--producers 3] [--phase-s 10] ... [octomap-rt-server flags]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <random>
#include <thread>

#include <CLI/CLI.hpp>

#include "cli/replay/scan_message.h"
#include "daemon/mapping_server.h"
#include "daemon/server_cli.h"
#include "octomap_rt/distance_box_chunk_t.hpp"
#include "octomap_rt/distance_points_reply_t.hpp"
#include "octomap_rt/distance_query_t.hpp"
#include "protocol/channels.h"
#include "scene/scan_set.h"

namespace {

using Clock = std::chrono::steady_clock;
using DQ = octomap_rt::distance_query_t;
const std::string kReply = "DISTANCE_BENCH_REPLY";

// Replies on the bench's channel, by request id: when the last message of each arrived.
struct Replies {
  std::mutex m;
  std::condition_variable cv;
  std::map<int64_t, int> remaining;  // messages still expected (box: num_chunks)
  std::map<int64_t, Clock::time_point> done;
  std::map<int64_t, std::string> errors;
  explicit Replies(ort::daemon::MappingServer& s) {
    s.lcm_loop().subscribe(kReply, [this](const lcm::ReceiveBuffer& rb, const std::string&) { on(rb); });
  }
  void on(const lcm::ReceiveBuffer& rb) {
    const auto now = Clock::now();
    octomap_rt::distance_box_chunk_t box;
    octomap_rt::distance_points_reply_t pts;
    int64_t id = 0;
    int total = 1;
    std::string error;
    if (box.decode(rb.data, 0, int(rb.data_size)) >= 0) {
      id = box.request_id, total = std::max(1, box.num_chunks), error = box.error;
    } else if (pts.decode(rb.data, 0, int(rb.data_size)) >= 0) {
      id = pts.request_id, error = pts.error;
    } else {
      return;
    }
    std::lock_guard lock(m);
    auto it = remaining.find(id);
    if (it == remaining.end()) it = remaining.emplace(id, total).first;
    if (!error.empty()) errors[id] = error, it->second = 1;
    if (--it->second == 0) done[id] = now, cv.notify_all();
  }
  // Seconds from `sent` to the last message of `id`; < 0 on timeout or error.
  double wait(int64_t id, Clock::time_point sent, double timeout_s) {
    std::unique_lock lock(m);
    if (!cv.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return done.count(id) > 0; })) return -1;
    if (errors.count(id)) {
      std::cerr << "request " << id << ": " << errors[id] << "\n";
      return -1;
    }
    return std::chrono::duration<double>(done[id] - sent).count();
  }
};

struct Stats {
  std::vector<double> ms;
  void add(double s) {
    if (s >= 0) ms.push_back(s * 1e3);
  }
  double pct(double p) const {
    if (ms.empty()) return -1;
    std::vector<double> v = ms;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, size_t(p / 100.0 * double(v.size())))];
  }
};

int64_t applied_total(ort::daemon::MappingServer& s) {
  int64_t n = 0;
  for (const auto& p : s.producer_stats()) n += p.applied;
  return n;
}
int64_t in_flight(ort::daemon::MappingServer& s, const std::string& robot) {
  for (const auto& p : s.producer_stats())
    if (p.robot_id == robot) return p.in_flight;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"octomap-rt-distance-bench: distance queries against the daemon in one process"};
  std::string graph = "../shared/data/octomap_share/scan_dat.graph", csv;
  int producers = 3, points = 1000, box_queries = 20, point_queries = 50;
  double phase_s = 10, box_rate = 10, max_distance = 2.0, box_x = 20, box_y = 20, box_z = 3;
  app.add_option("--graph", graph, "scans (ScanGraph) streamed in first and by the producers")->capture_default_str();
  app.add_option("--producers", producers, "producers streaming during the loaded phases")->capture_default_str();
  app.add_option("--phase-s", phase_s, "seconds of each streaming phase")->capture_default_str();
  app.add_option("--box-rate", box_rate, "box queries per second while streaming")->capture_default_str();
  app.add_option("--box-queries", box_queries, "box queries in the idle phase")->capture_default_str();
  app.add_option("--point-queries", point_queries, "point queries per phase")->capture_default_str();
  app.add_option("--points", points, "points per point query")->capture_default_str();
  app.add_option("--max-distance", max_distance, "[m]")->capture_default_str();
  app.add_option("--box-x", box_x, "box size [m]")->capture_default_str();
  app.add_option("--box-y", box_y)->capture_default_str();
  app.add_option("--box-z", box_z)->capture_default_str();
  app.add_option("--csv", csv, "append one line per phase");
  ort::daemon::ServerFlags flags;
  ort::daemon::add_server_flags(app, flags);
  CLI11_PARSE(app, argc, argv);
  ort::daemon::ServerConfig cfg = ort::daemon::to_server_config(flags);
  cfg.save_interval_s = 0;
  cfg.map_path.clear();

  const ort::ScanSet scans = ort::load_scan_graph(graph);
  lcm::LCM lc("memq://");
  ort::daemon::MappingServer server(cfg, lc, std::cerr);
  Replies replies(server);
  server.start();
  int64_t seq = 0;
  auto publish_scan = [&](const std::string& robot, size_t i, int64_t s) {
    ort::cli::ScanMessageFields f;
    f.robot_id = robot, f.seq = s, f.utime = s + 1;
    const auto msg = ort::cli::make_scan_message(scans.scans[i % scans.scans.size()], f);
    lc.publish(ort::cli::scan_channel(ort::protocol::kScanChannelPrefix, robot), &msg);
  };
  for (size_t i = 0; i < scans.scans.size(); ++i) {
    while (in_flight(server, "map") > 2) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    publish_scan("map", i, seq++);
  }
  while (applied_total(server) < int64_t(scans.scans.size())) std::this_thread::sleep_for(std::chrono::milliseconds(5));

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
  std::mt19937 rng(27);
  int64_t next_id = 1;
  auto box_query = [&] {
    DQ q{};
    q.request_id = next_id++, q.wait_seq = -1, q.client_id = "bench", q.reply_channel = kReply;
    q.mode = DQ::MODE_BOX, q.max_distance = max_distance, q.cell_voxels = 1;
    std::copy(bmin, bmin + 3, q.box_min), std::copy(bmax, bmax + 3, q.box_max);
    const auto t = Clock::now();
    lc.publish(ort::protocol::kQueryDistanceChannel, &q);
    return std::make_pair(q.request_id, t);
  };
  auto point_query = [&] {
    DQ q{};
    q.request_id = next_id++, q.wait_seq = -1, q.client_id = "bench-points", q.reply_channel = kReply;
    q.mode = DQ::MODE_POINTS, q.max_distance = max_distance, q.with_gradient = 1, q.cell_voxels = 1;
    for (int p = 0; p < points; ++p)
      for (int a = 0; a < 3; ++a) q.xyz.push_back(float(std::uniform_real_distribution<double>(bmin[a], bmax[a])(rng)));
    q.num_xyz = int32_t(q.xyz.size());
    const auto t = Clock::now();
    lc.publish(ort::protocol::kQueryDistanceChannel, &q);
    return std::make_pair(q.request_id, t);
  };

  std::ofstream out;
  if (!csv.empty()) {
    const bool fresh = !std::ifstream(csv).good();
    out.open(csv, std::ios::app);
    if (fresh) out << "phase,queries,p50_ms,p99_ms,max_ms,scans_per_s,producers,box_cells\n";
  }
  const int64_t box_cells = int64_t(std::lround(box_x / cfg.engine.resolution)) *
                            int64_t(std::lround(box_y / cfg.engine.resolution)) *
                            int64_t(std::lround(box_z / cfg.engine.resolution));
  auto report = [&](const std::string& phase, const Stats& s, double scans_per_s) {
    std::printf("%-22s queries %4zu  p50 %8.2f ms  p99 %8.2f ms  max %8.2f ms  scans/s %7.1f\n", phase.c_str(),
                s.ms.size(), s.pct(50), s.pct(99), s.pct(100), scans_per_s);
    if (out) {
      out << phase << "," << s.ms.size() << "," << s.pct(50) << "," << s.pct(99) << "," << s.pct(100) << ","
          << scans_per_s << "," << producers << "," << box_cells << "\n";
    }
  };
  std::printf("map: %zu scans of %s at %g m; box %g x %g x %g m (about %lld cells), max %g m\n", scans.scans.size(),
              graph.c_str(), cfg.engine.resolution, box_x, box_y, box_z, static_cast<long long>(box_cells),
              max_distance);

  // Idle: one query at a time.
  Stats idle_box, idle_points;
  for (int i = 0; i < box_queries; ++i) {
    const auto [id, t] = box_query();
    idle_box.add(replies.wait(id, t, 30));
  }
  report("box idle", idle_box, 0);
  for (int i = 0; i < point_queries; ++i) {
    const auto [id, t] = point_query();
    idle_points.add(replies.wait(id, t, 30));
  }
  report("points idle", idle_points, 0);

  // Streaming: producers keep 2 scans in flight each (as fast as the server maps).
  auto stream = [&](const std::function<void(std::atomic<bool>&)>& queries) {
    std::atomic<bool> stop{false};
    std::vector<std::thread> threads;
    for (int p = 0; p < producers; ++p)
      threads.emplace_back([&, p] {
        const std::string robot = "bench" + std::to_string(p);
        int64_t s = 0;
        for (size_t i = size_t(p); !stop; i += size_t(producers)) {
          while (!stop && in_flight(server, robot) >= 2) std::this_thread::sleep_for(std::chrono::microseconds(500));
          publish_scan(robot, i, s++);
        }
      });
    const int64_t before = applied_total(server);
    const auto t0 = Clock::now();
    queries(stop);
    while (std::chrono::duration<double>(Clock::now() - t0).count() < phase_s)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    const double scans_per_s =
        double(applied_total(server) - before) / std::chrono::duration<double>(Clock::now() - t0).count();
    stop = true;
    for (auto& t : threads) t.join();
    return scans_per_s;
  };
  Stats none;
  report("mapping alone", none, stream([](std::atomic<bool>&) {}));
  Stats loaded_box;
  const double with_boxes = stream([&](std::atomic<bool>&) {
    const auto t0 = Clock::now();
    std::vector<std::pair<int64_t, Clock::time_point>> sent;
    for (int i = 0; std::chrono::duration<double>(Clock::now() - t0).count() < phase_s; ++i) {
      sent.push_back(box_query());
      std::this_thread::sleep_until(
          t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>((i + 1) / box_rate)));
    }
    for (const auto& [id, t] : sent) loaded_box.add(replies.wait(id, t, 30));
  });
  report("mapping + boxes", loaded_box, with_boxes);
  Stats loaded_points;
  const double with_points = stream([&](std::atomic<bool>&) {
    for (int i = 0; i < point_queries; ++i) {
      const auto [id, t] = point_query();
      loaded_points.add(replies.wait(id, t, 30));
    }
  });
  report("mapping + points", loaded_points, with_points);
  server.stop();
  return 0;
}
