// octomap-rt-plan: an example planner on the query service. It asks the server for the 2D
// grid of a z band, plans a path between two points with A* over free cells (8-connected),
// checks the robot's clearance along the path with distance queries (the distance to the
// nearest obstacle at each cell's centre, at heights through the band, must be at least
// --radius: no obstacles grown on the client), replans around cells that fail, and prints
// the path with its smallest clearance.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <queue>
#include <vector>

#include <CLI/CLI.hpp>

#include "protocol/channels.h"
#include "protocol/lcm_url.h"
#include "protocol/limits.h"
#include "protocol/version.h"
#include "query_client/query_args.h"
#include "query_client/query_client.h"

namespace {

using ort::client::Grid;

struct Cell {
  int i, j;
};

// A* over cells whose state is free and not blocked; empty when there is no path.
std::vector<Cell> astar(const Grid& g, const std::vector<bool>& blocked, Cell from, Cell to) {
  const int w = g.header.width, h = g.header.height;
  auto idx = [w](int i, int j) { return size_t(j) * w + i; };
  auto ok = [&](int i, int j) {
    return i >= 0 && j >= 0 && i < w && j < h && g.cells[idx(i, j)] == 1 && !blocked[idx(i, j)];
  };
  std::vector<double> cost(size_t(w) * h, INFINITY);
  std::vector<size_t> parent(size_t(w) * h, SIZE_MAX);
  using Item = std::pair<double, size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  auto heuristic = [&](int i, int j) { return std::hypot(i - to.i, j - to.j); };
  if (!ok(from.i, from.j) || !ok(to.i, to.j)) return {};
  cost[idx(from.i, from.j)] = 0;
  open.push({heuristic(from.i, from.j), idx(from.i, from.j)});
  while (!open.empty()) {
    const size_t cur = open.top().second;
    open.pop();
    const int ci = int(cur % w), cj = int(cur / w);
    if (ci == to.i && cj == to.j) break;
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        if ((!di && !dj) || !ok(ci + di, cj + dj)) continue;
        // No corner cutting: a diagonal step needs both side cells free.
        if (di && dj && (!ok(ci + di, cj) || !ok(ci, cj + dj))) continue;
        const size_t n = idx(ci + di, cj + dj);
        const double c = cost[cur] + std::hypot(di, dj);
        if (c < cost[n]) {
          cost[n] = c, parent[n] = cur;
          open.push({c + heuristic(ci + di, cj + dj), n});
        }
      }
  }
  std::vector<Cell> path;
  for (size_t at = idx(to.i, to.j); at != SIZE_MAX; at = parent[at]) {
    path.push_back({int(at % w), int(at / w)});
    if (at == idx(from.i, from.j)) break;
  }
  if (path.empty() || path.back().i != from.i || path.back().j != from.j) return {};
  return {path.rbegin(), path.rend()};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"octomap-rt-plan: A* on the server's 2D grid, clearance checked with distance queries"};
  std::string from_s, to_s, z_s = "0.1:1.5", lcm_url, ns;
  double cell = 0, radius = 0.3, timeout_s = 10;
  bool json = false;
  app.add_option("--from", from_s, "start X,Y [m]")->required();
  app.add_option("--to", to_s, "goal X,Y [m]")->required();
  app.add_option("--z", z_s, "z band MIN:MAX [m] the robot occupies")->capture_default_str();
  app.add_option("--cell", cell, "grid cell [m] (a multiple of the resolution; 0: the resolution)");
  app.add_option("--radius", radius, "robot radius [m]: the clearance every path cell needs")->capture_default_str();
  app.add_option("--lcm-url", lcm_url, "LCM URL (default: $LCM_DEFAULT_URL, else the host-local udpm URL)");
  app.add_option("--timeout", timeout_s, "seconds to wait for each answer")->capture_default_str();
  app.add_option("--namespace", ns,
                 std::string("the server's namespace (its --namespace); default: $") + ort::protocol::kNamespaceEnv);
  app.add_flag("--json", json,
               "one JSON document on stdout: {\"found\", \"reason\", \"snapshot_id\", \"cells\", \"length_m\", "
               "\"clearance_m\", \"attempts\", \"path\": [[x, y], ...]}");
  app.set_version_flag("--version", std::string("octomap-rt-plan ") + OCTOMAP_RT_VERSION + " (protocol version " +
                                        std::to_string(ort::protocol::kProtocolVersion) + ")");
  CLI11_PARSE(app, argc, argv);
  // Text for people, or one JSON document for scripts (--json).
  auto no_path = [&](const std::string& why, int64_t snapshot) {
    if (json)
      std::printf("{\"found\": false, \"reason\": \"%s\", \"snapshot_id\": %lld}\n", why.c_str(), (long long)snapshot);
    else
      std::printf("%s\n", why.c_str());
    return 3;
  };
  try {
    const auto from = ort::client::parse_numbers(from_s, 2), to = ort::client::parse_numbers(to_s, 2);
    double z0, z1;
    ort::client::parse_range(z_s, z0, z1);
    ort::client::QueryClient client(ort::protocol::lcm_url_or_default(lcm_url), "planner-" + std::to_string(::getpid()),
                                    std::chrono::milliseconds(static_cast<int64_t>(timeout_s * 1000)),
                                    ort::protocol::namespace_from(ns));
    const Grid g = client.grid(z0, z1, cell, nullptr);
    if (g.header.status != 0) throw std::runtime_error("grid refused: " + g.header.error);
    const double cs = g.header.cell_size;
    auto cell_of = [&](double x, double y) {
      return Cell{int(std::floor((x - g.header.origin_x) / cs)), int(std::floor((y - g.header.origin_y) / cs))};
    };
    auto centre = [&](Cell c, int k) {
      return (k ? g.header.origin_y + (c.j + 0.5) * cs : g.header.origin_x + (c.i + 0.5) * cs);
    };
    if (!json)
      std::printf("grid: %d x %d cells of %g m, map state %lld\n", g.header.width, g.header.height, cs,
                  (long long)g.header.snapshot_id);
    std::vector<bool> blocked(g.cells.size(), false);
    for (int attempt = 1; attempt <= 8; ++attempt) {
      const std::vector<Cell> path = astar(g, blocked, cell_of(from[0], from[1]), cell_of(to[0], to[1]));
      if (path.empty()) {
        char why[160];
        std::snprintf(why, sizeof why, "no path from (%g, %g) to (%g, %g) through free cells", from[0], from[1], to[0],
                      to[1]);
        return no_path(why, g.header.snapshot_id);
      }
      // Each cell's centre at heights through the band, one resolution apart at most.
      const int levels = std::max(1, int(std::ceil((z1 - z0) / cs)) + 1);
      std::vector<float> xyz;
      for (const Cell& c : path)
        for (int l = 0; l < levels; ++l)
          xyz.insert(xyz.end(), {float(centre(c, 0)), float(centre(c, 1)),
                                 float(levels == 1 ? z0 : z0 + (z1 - z0) * l / (levels - 1))});
      ort::client::DistanceRequest need;
      need.max_distance = radius + cs;  // enough to tell clear from not
      int failed = 0;
      float lowest = float(need.max_distance);
      const size_t per_query = size_t(ort::protocol::kMaxQueryPoints / levels) * levels;
      for (size_t first = 0; first < xyz.size(); first += 3 * per_query) {
        const std::vector<float> part(xyz.begin() + first, xyz.begin() + std::min(xyz.size(), first + 3 * per_query));
        const auto r = client.distance_points(part, need);
        if (r.status != 0) throw std::runtime_error("distance query refused: " + r.error);
        for (int k = 0; k < r.num_points; ++k) {
          lowest = std::min(lowest, r.distance[k]);
          const Cell c = path[(first / 3 + k) / levels];
          if (r.distance[k] < radius && !blocked[size_t(c.j) * g.header.width + c.i]) {
            blocked[size_t(c.j) * g.header.width + c.i] = true;
            ++failed;
          }
        }
      }
      if (failed) {
        if (!json)
          std::printf("attempt %d: %zu cells, %d closer than %g m to an obstacle; replanning\n", attempt, path.size(),
                      failed, radius);
        continue;
      }
      double length = 0;
      for (size_t k = 1; k < path.size(); ++k)
        length += cs * std::hypot(path[k].i - path[k - 1].i, path[k].j - path[k - 1].j);
      if (json) {
        std::printf(
            "{\"found\": true, \"snapshot_id\": %lld, \"cells\": %zu, \"length_m\": %.3f, \"clearance_m\": %.3f, "
            "\"attempts\": %d, \"path\": [",
            (long long)g.header.snapshot_id, path.size(), length, lowest, attempt);
        for (size_t k = 0; k < path.size(); ++k)
          std::printf("%s[%.3f, %.3f]", k ? ", " : "", centre(path[k], 0), centre(path[k], 1));
        std::printf("]}\n");
        return 0;
      }
      std::printf("path: %zu cells, %.2f m, clearance %.2f m >= %g m (%d attempts)\n", path.size(), length, lowest,
                  radius, attempt);
      for (const Cell& c : path) std::printf("  %.3f %.3f\n", centre(c, 0), centre(c, 1));
      return 0;
    }
    char why[96];
    std::snprintf(why, sizeof why, "no path with %g m clearance after 8 attempts", radius);
    return no_path(why, g.header.snapshot_id);
  } catch (const std::exception& e) {
    std::cerr << "octomap-rt-plan: " << e.what() << "\n";
    return 1;
  }
}
