// octomap-rt-shard-query-bench --lcm-url URL --shards NS --whole NS GRAPH [--rounds 200]
//
// Queries routed across a shard set against the same queries to one daemon holding the same
// scans (both already running and fed, e.g. by docs/bench/dev/issue26-routed.sh): per round a
// points query (every k-th end point of the graph's scans, shifted off the surfaces) and a rays
// query (from each scan's sensor towards its end points, stopping at unknown space), to the one
// daemon and to the shards (client/shard_client/ShardQueries), alternated so the machine's
// load falls on both alike. Prints p50 / p99 of each and their ratio, and how many answers
// differ between the two (expected 0: the routed answer is the one daemon's).
#include <algorithm>
#include <cstdio>
#include <vector>

#include <CLI/CLI.hpp>

#include "core/clock.h"
#include "query_client/query_client.h"
#include "scene/scan_set.h"
#include "shard_client/shard_queries.h"
#include "shard_client/shard_roster.h"

namespace {

using ort::ms_since;
using ort::SteadyClock;

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * double(v.size())))];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("octomap-rt-shard-query-bench: routed query latency across a shard set against one daemon");
  std::string url, shards_ns, whole_ns, graph;
  int rounds = 200, points = 1000, rays = 200;
  double max_range = 30;
  app.add_option("graph", graph, "the ScanGraph both maps were fed (.graph)")->required();
  app.add_option("--lcm-url", url, "LCM URL of both")->required();
  app.add_option("--shards", shards_ns, "the shard set's namespace")->required();
  app.add_option("--whole", whole_ns, "the one daemon's namespace")->required();
  app.add_option("--rounds", rounds, "queries of each kind to each")->capture_default_str();
  app.add_option("--points", points, "points a points query")->capture_default_str();
  app.add_option("--rays", rays, "rays a rays query")->capture_default_str();
  app.add_option("--max-range", max_range, "[m] of the rays")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const ort::ScanSet set = ort::load_scan_graph(graph);
  std::vector<float> xyz, origins, directions;
  size_t total = 0;
  for (const auto& s : set.scans) total += s.points.size();
  const size_t step = std::max<size_t>(1, total / size_t(std::max(points, rays)));
  for (const auto& s : set.scans) {
    const octomap::Pointcloud w = ort::world_points(s);
    const octomap::point3d o = ort::sensor_origin(s);
    for (size_t i = 0; i < w.size(); i += step) {
      const float shift = 0.05f * float((xyz.size() / 3) % 13) - 0.3f;
      if (xyz.size() < 3 * size_t(points)) xyz.insert(xyz.end(), {w[i].x() + shift, w[i].y(), w[i].z() - shift});
      if (origins.size() < 3 * size_t(rays)) {
        origins.insert(origins.end(), {o.x(), o.y(), o.z()});
        directions.insert(directions.end(), {w[i].x() - o.x(), w[i].y() - o.y(), w[i].z() - o.z()});
      }
    }
  }
  const ort::client::ShardRoster roster = ort::client::discover_shards(url, shards_ns, 5);
  if (!roster.complete()) {
    std::fprintf(stderr, "octomap-rt-shard-query-bench: %s\n", roster.shortfall(ort::now_utime(), 3).c_str());
    return 1;
  }
  const auto timeout = std::chrono::seconds(10);
  ort::client::ShardQueries routed(url, "bench_routed", timeout, shards_ns, *roster.set(), roster.resolution());
  ort::client::QueryClient whole(url, "bench_whole", timeout, whole_ns);
  std::vector<double> pw, pr, rw, rr;
  int64_t differ = 0, partial = 0, cut = 0;
  for (int k = 0; k < rounds; ++k) {
    auto t = SteadyClock::now();
    const auto a = whole.points(xyz);
    pw.push_back(ms_since(t));
    t = SteadyClock::now();
    const auto b = routed.points(xyz);
    pr.push_back(ms_since(t));
    partial += b.shards.partial();
    differ += a.occupancy != b.reply.occupancy || a.probability != b.reply.probability;
    t = SteadyClock::now();
    const auto c = whole.rays(origins, directions, float(max_range), false);
    rw.push_back(ms_since(t));
    t = SteadyClock::now();
    const auto d = routed.rays(origins, directions, float(max_range), false);
    rr.push_back(ms_since(t));
    partial += d.shards.partial();
    cut += c.cut != 0 || d.reply.cut != 0;
    differ += c.cut == 0 && d.reply.cut == 0 && (c.hit != d.reply.hit || c.end_xyz != d.reply.end_xyz);
  }
  std::printf(
      "%d rounds; %zu points a points query, %zu rays a rays query (max range %g m, stopping at unknown); "
      "%u shards\n",
      rounds, xyz.size() / 3, origins.size() / 3, max_range, roster.set()->count);
  std::printf("%-8s %12s %12s %12s %12s %10s\n", "query", "one p50 ms", "one p99 ms", "set p50 ms", "set p99 ms",
              "p99 ratio");
  std::printf("%-8s %12.2f %12.2f %12.2f %12.2f %10.2f\n", "points", percentile(pw, 0.5), percentile(pw, 0.99),
              percentile(pr, 0.5), percentile(pr, 0.99), percentile(pr, 0.99) / percentile(pw, 0.99));
  std::printf("%-8s %12.2f %12.2f %12.2f %12.2f %10.2f\n", "rays", percentile(rw, 0.5), percentile(rw, 0.99),
              percentile(rr, 0.5), percentile(rr, 0.99), percentile(rr, 0.99) / percentile(rw, 0.99));
  std::printf("answers differing from the one daemon's: %lld; partial: %lld; cut by a bound: %lld\n", (long long)differ,
              (long long)partial, (long long)cut);
  return differ == 0 && partial == 0 ? 0 : 1;
}
