// Query latency against a running octomap-rt-server: queries of three kinds in turn at a
// fixed total rate (a 1000-point query, a 100-ray query, a 5 m box count), open loop (each
// is sent at its time whether or not earlier ones were answered, as planners on a timer
// do), each timed from its publication to its reply's arrival, until --duration passes or
// --until-file exists. The queries come from a scan graph (the one the producers send):
// points near its scans' end points (jittered, so occupied, free and unknown mix), rays
// from its sensor positions towards its end points, boxes centred on its sensor positions.
// Prints p50 / p99 / max per kind (text, or one JSON document with --json).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "core/clock.h"
#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/box_reply_t.hpp"
#include "octomap_rt/occupancy_query_t.hpp"
#include "octomap_rt/occupancy_reply_t.hpp"
#include "octomap_rt/ray_query_t.hpp"
#include "octomap_rt/ray_reply_t.hpp"
#include "protocol/channels.h"
#include "protocol/lcm_url.h"
#include "protocol/limits.h"
#include "scene/scan_set.h"

namespace {

using ort::seconds_since;
using ort::SteadyClock;

using Reply = octomap_rt::occupancy_reply_t;
struct Options {
  std::string graph, lcm_url = ort::protocol::kDefaultLcmUrl, until_file, client_id = "query-bench";
  double rate = 100, duration_s = 30, box_m = 5, jitter_m = 0.3, ray_range_m = 30;
  int points = 1000, rays = 100;
  unsigned seed = 1;
  bool json = false;
};

// Where the queries are drawn from.
struct Scene {
  std::vector<octomap::point3d> ends, sensors;
};

Scene load_scene(const std::string& path) {
  std::streambuf* out = std::cout.rdbuf(nullptr);  // OctoMap's reader talks on stdout
  const ort::ScanSet set = ort::load_scan_graph(path);
  std::cout.rdbuf(out);
  Scene s;
  for (const ort::PosedScan& scan : set.scans) {
    s.sensors.push_back(ort::sensor_origin(scan));
    const octomap::Pointcloud w = ort::world_points(scan);
    for (size_t i = 0; i < w.size(); i += 7) s.ends.push_back(w[i]);  // a sample is enough
  }
  if (s.ends.empty() || s.sensors.empty()) throw std::runtime_error(path + ": no scans with points");
  return s;
}

// Each kind is its own client (<client-id>-points, -rays, -boxes), as three planner parts
// would be: each has its own queue at the server (--query-queue).
const char* const kKindSuffix[3] = {"-points", "-rays", "-boxes"};

template <class Q>
void address(Q& q, int64_t id, int kind, const Options& o, const std::string& reply_channel) {
  q.utime = ort::now_utime();
  q.request_id = id;
  q.min_snapshot_id = 0;
  q.wait_seq = -1;
  q.wait_timeout_ms = 0;
  q.client_id = o.client_id + kKindSuffix[kind];
  q.reply_channel = reply_channel;
  q.wait_robot_id = "";
}

// Makes the queries of the three kinds, ready to publish.
class Queries {
 public:
  Queries(const Scene& scene, const Options& o, std::string reply_channel)
      : scene_(scene), o_(o), reply_(std::move(reply_channel)), rng_(o.seed) {}

  void publish(lcm::LCM& lc, int kind, int64_t id) {
    if (kind == 0) {
      octomap_rt::occupancy_query_t q{};
      address(q, id, kind, o_, reply_);
      for (int i = 0; i < o_.points; ++i) {
        const octomap::point3d& p = pick(scene_.ends);
        q.xyz.insert(q.xyz.end(), {p.x() + jitter(), p.y() + jitter(), p.z() + jitter()});
      }
      q.num_xyz = static_cast<int32_t>(q.xyz.size());
      lc.publish(ort::protocol::kQueryChannel, &q);
    } else if (kind == 1) {
      octomap_rt::ray_query_t q{};
      address(q, id, kind, o_, reply_);
      q.max_range = static_cast<float>(o_.ray_range_m);
      for (int i = 0; i < o_.rays; ++i) {
        const octomap::point3d& from = pick(scene_.sensors);
        octomap::point3d d = pick(scene_.ends) - from;
        if (d.norm() < 1e-3) d = octomap::point3d(1, 0, 0);
        q.origin_xyz.insert(q.origin_xyz.end(), {from.x(), from.y(), from.z()});
        q.direction_xyz.insert(q.direction_xyz.end(), {d.x(), d.y(), d.z()});
      }
      q.num_xyz = static_cast<int32_t>(q.origin_xyz.size());
      lc.publish(ort::protocol::kQueryRaysChannel, &q);
    } else {
      octomap_rt::box_query_t q{};
      address(q, id, kind, o_, reply_);
      q.mode = octomap_rt::box_query_t::MODE_COUNTS;
      const octomap::point3d& c = pick(scene_.sensors);
      const double h = o_.box_m / 2;
      q.boxes = {c.x() - h, c.y() - h, c.z() - h, c.x() + h, c.y() + h, c.z() + h};
      q.num_values = 6;
      lc.publish(ort::protocol::kQueryBoxesChannel, &q);
    }
  }

 private:
  const octomap::point3d& pick(const std::vector<octomap::point3d>& v) {
    return v[std::uniform_int_distribution<size_t>(0, v.size() - 1)(rng_)];
  }
  float jitter() { return std::uniform_real_distribution<float>(-o_.jitter_m, o_.jitter_m)(rng_); }

  const Scene& scene_;
  const Options& o_;
  std::string reply_;
  std::mt19937 rng_;
};

struct Kind {
  std::string name;
  std::vector<double> ms;
  int64_t sent = 0, busy = 0, errors = 0;
  std::string last_error;
};

// Replies matched to their queries by request id; latency = arrival - publication.
class Ledger {
 public:
  explicit Ledger(std::vector<Kind>& kinds) : kinds_(kinds) {}
  void sent(int64_t id, int kind, SteadyClock::time_point t) {
    std::lock_guard lock(m_);
    open_[id] = {kind, t};
    kinds_[kind].sent++;
  }
  void on_reply(const lcm::ReceiveBuffer* rb, const std::string&) {
    const auto now = SteadyClock::now();
    int64_t id = 0;
    int8_t status = 0;
    std::string error;
    if (!decode<Reply>(rb, id, status, error) && !decode<octomap_rt::ray_reply_t>(rb, id, status, error) &&
        !decode<octomap_rt::box_reply_t>(rb, id, status, error))
      return;
    std::lock_guard lock(m_);
    auto it = open_.find(id);
    if (it == open_.end()) return;
    Kind& k = kinds_[it->second.first];
    if (status == Reply::REPLY_OK)
      k.ms.push_back(std::chrono::duration<double, std::milli>(now - it->second.second).count());
    else if (status == Reply::REPLY_BUSY)
      k.busy++;
    else
      k.errors++, k.last_error = error;
    open_.erase(it);
  }
  size_t open() {
    std::lock_guard lock(m_);
    return open_.size();
  }

 private:
  template <class M>
  static bool decode(const lcm::ReceiveBuffer* rb, int64_t& id, int8_t& status, std::string& error) {
    M m;
    if (m.decode(rb->data, 0, static_cast<int>(rb->data_size)) < 0) return false;
    id = m.request_id, status = m.status, error = m.error;
    return true;
  }

  std::mutex m_;
  std::vector<Kind>& kinds_;
  std::map<int64_t, std::pair<int, SteadyClock::time_point>> open_;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * static_cast<double>(v.size())));
  return v[std::clamp<size_t>(rank, 1, v.size()) - 1];
}

std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

void report(const std::vector<Kind>& kinds, const Options& o, double seconds, int64_t sent) {
  if (o.json) {
    std::cout << "{\"seconds\":" << num(seconds) << ",\"queries\":" << sent << ",\"rate_per_s\":" << num(sent / seconds)
              << ",\"kinds\":{";
    for (size_t i = 0; i < kinds.size(); ++i) {
      const Kind& k = kinds[i];
      std::cout << (i ? "," : "") << "\"" << k.name << "\":{\"sent\":" << k.sent << ",\"answered\":" << k.ms.size()
                << ",\"p50_ms\":" << num(percentile(k.ms, 50)) << ",\"p99_ms\":" << num(percentile(k.ms, 99))
                << ",\"max_ms\":" << num(percentile(k.ms, 100)) << ",\"busy\":" << k.busy << ",\"errors\":" << k.errors
                << ",\"unanswered\":" << k.sent - int64_t(k.ms.size()) - k.busy - k.errors << "}";
    }
    std::cout << "}}\n";
    return;
  }
  std::printf("%lld queries sent in %.1f s (%.1f/s)\n", (long long)sent, seconds, sent / seconds);
  std::printf("%-18s %7s %9s %9s %9s %9s %6s %7s %10s\n", "query", "sent", "answered", "p50 ms", "p99 ms", "max ms",
              "busy", "errors", "unanswered");
  for (const Kind& k : kinds)
    std::printf("%-18s %7lld %9zu %9.2f %9.2f %9.2f %6lld %7lld %10lld\n", k.name.c_str(), (long long)k.sent,
                k.ms.size(), percentile(k.ms, 50), percentile(k.ms, 99), percentile(k.ms, 100), (long long)k.busy,
                (long long)k.errors, (long long)(k.sent - int64_t(k.ms.size()) - k.busy - k.errors));
  for (const Kind& k : kinds)
    if (!k.last_error.empty()) std::printf("%s: last error: %s\n", k.name.c_str(), k.last_error.c_str());
}

// Sends at the rate until the duration passes or the stop file exists; returns how many.
int64_t send_all(lcm::LCM& lc, Queries& make, Ledger& ledger, const Options& o) {
  const auto period = std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(1.0 / o.rate));
  const auto start = SteadyClock::now();
  auto next = start;
  int64_t sent = 0;
  for (;; ++sent) {
    if (seconds_since(start) >= o.duration_s) break;
    if (!o.until_file.empty() && std::filesystem::exists(o.until_file)) break;
    const int kind = static_cast<int>(sent % 3);
    ledger.sent(sent + 1, kind, SteadyClock::now());
    make.publish(lc, kind, sent + 1);
    next += period;
    if (next > SteadyClock::now())
      std::this_thread::sleep_until(next);
    else
      next = SteadyClock::now();  // behind (publishing took longer): no burst to catch up
  }
  return sent;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "octomap-rt-query-bench: latency of point, ray and box queries against a running octomap-rt-server, "
      "sent open loop at a fixed rate (docs/BENCHMARKS.md \"Queries\")"};
  Options o;
  app.add_option("--graph", o.graph, "scan graph the queries are drawn from (the producers' scans)")->required();
  app.add_option("--lcm-url", o.lcm_url, "LCM URL")->capture_default_str();
  app.add_option("--rate", o.rate, "queries per second, all kinds together")
      ->check(CLI::Range(0.1, 10000.0))
      ->capture_default_str();
  app.add_option("--duration", o.duration_s, "seconds to send for")->capture_default_str();
  app.add_option("--until-file", o.until_file, "stop sending as soon as this file exists");
  app.add_option("--points", o.points, "points per point query")
      ->check(CLI::Range(int64_t{1}, ort::protocol::kMaxQueryPoints))
      ->capture_default_str();
  app.add_option("--rays", o.rays, "rays per ray query")
      ->check(CLI::Range(int64_t{1}, ort::protocol::kMaxQueryRays))
      ->capture_default_str();
  app.add_option("--ray-range", o.ray_range_m, "max range of the rays [m]")->capture_default_str();
  app.add_option("--box", o.box_m, "side of the box queries [m]")->capture_default_str();
  app.add_option("--seed", o.seed, "random seed")->capture_default_str();
  app.add_option("--client-id", o.client_id,
                 "client id prefix: the kinds are clients ID-points, ID-rays, ID-boxes (replies on " +
                     std::string(ort::protocol::kQueryReplyPrefix) + "<ID>)")
      ->capture_default_str();
  app.add_flag("--json", o.json, "one JSON document on stdout");
  CLI11_PARSE(app, argc, argv);
  try {
    const Scene scene = load_scene(o.graph);
    std::vector<Kind> kinds(3);
    kinds[0].name = std::to_string(o.points) + "-point query";
    kinds[1].name = std::to_string(o.rays) + "-ray query";
    kinds[2].name = (std::ostringstream() << o.box_m).str() + " m box count";
    Ledger ledger(kinds);
    lcm::LCM lc(o.lcm_url);
    if (!lc.good()) throw std::runtime_error("LCM could not start on '" + o.lcm_url + "'");
    std::string reply_channel = std::string(ort::protocol::kQueryReplyPrefix) + o.client_id;
    for (char& c : reply_channel) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    lc.subscribe(reply_channel, &Ledger::on_reply, &ledger);  // before the handling thread starts
    std::atomic<bool> stop{false};
    std::thread receiver([&] {
      while (!stop) lc.handleTimeout(50);
    });
    Queries make(scene, o, reply_channel);
    const auto start = SteadyClock::now();
    const int64_t sent = send_all(lc, make, ledger, o);
    const double seconds = seconds_since(start);
    for (int i = 0; i < 100 && ledger.open() > 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    stop = true;
    receiver.join();
    report(kinds, o, seconds, sent);
  } catch (const std::exception& e) {
    std::cerr << "octomap-rt-query-bench: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
