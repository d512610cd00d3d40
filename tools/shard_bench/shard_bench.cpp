// octomap-rt-shard-bench GRAPH -r RES [--shards 1,2,3,4] [--depth 13] [--backend cpu-grid]
//                        [--rule hash|boxes] [--clip]
//
// One process, one thread a stage: every scan is encoded as a robot sends it (scan_t), decoded
// as the daemon's LCM thread decodes it, shot once (every shard walks every ray: the walk is
// the same for all) and, for each set size N, cut to each shard's regions and applied to that
// shard's tree. Prints per scan: the bus bytes, decode and walk time (paid by every shard), the
// cut, and the octree update of the busiest shard against one daemon's; then whether the
// merged map equals the one-daemon map node for node. Times are of this process on this
// machine; with a core per daemon, a set's rate is bounded by decode + walk + cut + its
// busiest shard's update (docs/BENCHMARKS.md, "Shards"). With --only-shard i the process keeps
// shard i of each set only: N such processes pinned to N cores side by side are the set with a
// core per daemon (docs/bench/gpu/issue26-pinned.sh sums them up). With --clip each shard
// shoots the scan itself with the daemon's ray clip (MapEngine::set_ray_clip: the rays that
// meet none of its regions left out): the walk is then per shard (its busiest and mean shard
// printed, with the rays it left out). --rule boxes: N slabs of equal width along x over the
// scans' points (the first and last open), instead of the hash rule.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <sstream>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/replay/scan_message.h"
#include "core/backend_kind.h"
#include "core/clock.h"
#include "daemon/intake/scan_to_map.h"
#include "daemon/pipeline/shard_filter.h"
#include "engine/map_engine.h"
#include "map_client/shard_merge.h"
#include "protocol/scan_decode.h"
#include "scene/scan_set.h"

namespace {

using ort::ms_since;
using ort::SteadyClock;

std::vector<int> parse_list(const std::string& s) {
  std::vector<int> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');) out.push_back(std::stoi(item));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("octomap-rt-shard-bench: per-shard cost of a shard set against one daemon");
  std::string input, backend = "cpu-grid", shards = "1,2,3,4";
  double res = 0.1, max_range = -1;
  unsigned depth = ort::protocol::kDefaultShardRegionDepth;
  int repeat = 1, only = -1;
  bool clip = false;
  std::string rule = "hash";
  app.add_option("input", input, "ScanGraph file (.graph)")->required();
  app.add_option("-r,--resolution", res, "[m]")->capture_default_str();
  app.add_option("--max-range", max_range, "[m]; < 0: none")->capture_default_str();
  app.add_option("--shards", shards, "set sizes, comma-separated")->capture_default_str();
  app.add_option("--depth", depth, "region depth (1..16)")->capture_default_str();
  app.add_option("--backend", backend, "ray back end (cpu, cpu-grid, vulkan)")->capture_default_str();
  app.add_option("--repeat", repeat, "go over the scans this many times")->capture_default_str();
  app.add_option("--only-shard", only, "keep only shard i of each set (-1: every shard)")->capture_default_str();
  app.add_flag("--clip", clip, "each shard shoots with the daemon's ray clip (walk times per shard)");
  app.add_option("--rule", rule, "hash, or boxes (slabs along x)")
      ->check(CLI::IsMember({"hash", "boxes"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const ort::ScanSet set = ort::load_scan_graph(input);
  ort::EngineOptions opts;
  opts.resolution = res, opts.max_range = max_range;
  if (!ort::parse_backend(backend, opts.backend.kind)) {
    std::fprintf(stderr, "octomap-rt-shard-bench: unknown back end '%s'\n", backend.c_str());
    return 2;
  }
  opts.octree.threads = 1;  // one core per daemon
  ort::MapEngine engine(opts);
  const std::vector<int> sizes = parse_list(shards);
  for (int n : sizes)
    if (n < 1 || (only >= 0 && only >= n)) {
      std::fprintf(stderr, "octomap-rt-shard-bench: set size %d (--only-shard %d needs every size above it)\n", n,
                   only);
      return 2;
    }
  struct PerSize {
    std::vector<std::unique_ptr<octomap::OcTree>> trees;
    std::vector<ort::daemon::ShardFilter> filters;
    std::vector<double> cut_ms, apply_ms, walk_ms;
    std::vector<uint64_t> voxels, clipped;
  };
  double x_lo = 1e300, x_hi = -1e300;  // the slabs' span (--rule boxes)
  for (const ort::PosedScan& scan : set.scans)
    for (const octomap::point3d& p : ort::world_points(scan))
      x_lo = std::min(x_lo, double(p.x())), x_hi = std::max(x_hi, double(p.x()));
  std::vector<PerSize> runs(sizes.size());
  for (size_t s = 0; s < sizes.size(); ++s)
    for (int i = 0; i < sizes[s]; ++i) {
      ort::protocol::ShardSet sh;
      if (sizes[s] > 1) sh.index = i, sh.count = sizes[s], sh.rule = ort::protocol::ShardRule::kHash;
      sh.region_depth = depth;
      if (sizes[s] > 1 && rule == "boxes") {
        sh.rule = ort::protocol::ShardRule::kBoxes;
        const double inf = std::numeric_limits<double>::infinity(), w = (x_hi - x_lo) / sizes[s];
        for (int j = 0; j < sizes[s]; ++j) {
          const double lo[3] = {j == 0 ? -inf : x_lo + j * w, -inf, -inf};
          const double hi[3] = {j + 1 == sizes[s] ? inf : x_lo + (j + 1) * w, inf, inf};
          sh.boxes.push_back(ort::protocol::region_box_of(lo, hi, res, depth));
        }
      }
      runs[s].trees.push_back(engine.make_tree());
      runs[s].filters.emplace_back(sh);
      runs[s].cut_ms.push_back(0), runs[s].apply_ms.push_back(0), runs[s].walk_ms.push_back(0);
      runs[s].voxels.push_back(0), runs[s].clipped.push_back(0);
    }
  double decode_ms = 0, walk_ms = 0;
  uint64_t bytes = 0, scans = 0;
  ort::ShotScan shot;
  {  // warm-up, untimed: the walk's grid takes its page faults on the first scan of a size
    const octomap_rt::scan_t msg = ort::cli::make_scan_message(set.scans[0], ort::cli::ScanMessageFields{});
    const octomap::pose6d pose = ort::daemon::scan_pose(msg);
    engine.shoot_posed_xyz(pose, pose.trans(), std::span<const float>(msg.xyz.data(), msg.xyz.size()), max_range, shot);
  }
  for (int rep = 0; rep < repeat; ++rep)
    for (size_t k = 0; k < set.scans.size(); ++k, ++scans) {
      ort::cli::ScanMessageFields f;
      f.robot_id = "bench", f.seq = static_cast<int64_t>(scans);
      const octomap_rt::scan_t msg = ort::cli::make_scan_message(set.scans[k], f);
      std::vector<uint8_t> wire(static_cast<size_t>(msg.getEncodedSize()));
      msg.encode(wire.data(), 0, static_cast<int>(wire.size()));
      bytes += wire.size();
      octomap_rt::scan_t got;
      auto t = SteadyClock::now();
      ort::protocol::decode_scan(wire.data(), wire.size(), got);
      decode_ms += ms_since(t);
      const octomap::pose6d pose = ort::daemon::scan_pose(got);
      const std::span<const float> xyz(got.xyz.data(), got.xyz.size());
      if (!clip) {  // one walk serves every shard: they all walk every ray alike
        t = SteadyClock::now();
        engine.shoot_posed_xyz(pose, pose.trans(), xyz, max_range, shot);
        walk_ms += ms_since(t);
      }
      for (PerSize& run : runs)
        for (size_t i = 0; i < run.trees.size(); ++i) {
          if (only >= 0 && i != size_t(only)) continue;
          if (clip) {
            const ort::daemon::ShardFilter& f = run.filters[i];
            if (f.active())
              engine.set_ray_clip([&f](const ort::KeyBox& b) { return f.may_hold(b); });
            else
              engine.set_ray_clip({});
            t = SteadyClock::now();
            engine.shoot_posed_xyz(pose, pose.trans(), xyz, max_range, shot);
            run.walk_ms[i] += ms_since(t);
            run.clipped[i] += shot.clipped_rays;
          }
          ort::ShotScan mine = shot;
          t = SteadyClock::now();
          run.filters[i].keep_owned(mine);
          run.cut_ms[i] += ms_since(t);
          run.voxels[i] += mine.voxels.size();
          t = SteadyClock::now();
          engine.apply(mine, *run.trees[i]);
          run.apply_ms[i] += ms_since(t);
        }
    }
  const double n = static_cast<double>(scans);
  std::printf("%s: %llu scans, %.1f MB a scan on the bus, resolution %g m, regions at depth %u, back end %s\n",
              input.c_str(), (unsigned long long)scans, bytes / n / 1e6, res, depth, backend.c_str());
  uint64_t rays = 0;
  for (const ort::PosedScan& scan : set.scans) rays += scan.points.size();
  rays *= static_cast<uint64_t>(repeat);
  if (clip)
    std::printf("every shard: decode %.2f ms a scan; each shard walks its own rays (--clip, rule %s)\n", decode_ms / n,
                rule.c_str());
  else
    std::printf("every shard: decode %.2f ms, walk %.2f ms a scan (rule %s)\n", decode_ms / n, walk_ms / n,
                rule.c_str());
  std::printf("%6s %12s %14s %14s %12s %12s %12s %12s %14s %10s %14s\n", "shards", "cut ms", "update ms max",
              "update ms mean", "voxels max", "walk ms max", "walk ms mean", "rays kept", "bound scans/s", "merged",
              "voxels max/mean");
  const octomap::OcTree* whole = nullptr;
  for (size_t s = 0; s < sizes.size(); ++s)
    if (sizes[s] == 1) whole = runs[s].trees[0].get();
  for (size_t s = 0; s < sizes.size(); ++s) {
    const PerSize& r = runs[s];
    const double cut = *std::max_element(r.cut_ms.begin(), r.cut_ms.end()) / n;
    const double upd_max = *std::max_element(r.apply_ms.begin(), r.apply_ms.end()) / n;
    double upd_sum = 0;
    for (double a : r.apply_ms) upd_sum += a;
    if (only >= 0) upd_sum = upd_max * n;  // the one shard kept: the mean is its own
    const uint64_t vox = *std::max_element(r.voxels.begin(), r.voxels.end());
    uint64_t vox_sum = 0;
    for (uint64_t v : r.voxels) vox_sum += v;
    // The busiest shard's voxels against the mean shard's: the set's load imbalance (every
    // shard kept; with --only-shard the others are not counted).
    const double imbalance = only >= 0 || vox_sum == 0 ? 0 : double(vox) * double(r.voxels.size()) / double(vox_sum);
    // Without --clip every shard's walk is the one shared walk.
    const size_t kept_shards = only >= 0 ? 1 : r.trees.size();
    double walk_max = walk_ms / n, walk_sum = 0;
    uint64_t clipped_sum = 0;
    if (clip) {
      walk_max = *std::max_element(r.walk_ms.begin(), r.walk_ms.end()) / n;
      for (double w : r.walk_ms) walk_sum += w;
      for (uint64_t c : r.clipped) clipped_sum += c;
    } else {
      walk_sum = walk_ms * static_cast<double>(kept_shards);
    }
    const double kept = 1.0 - double(clipped_sum) / double(rays * kept_shards);
    std::string merged = "-";
    if (whole && sizes[s] > 1 && only < 0) {
      std::vector<const octomap::OcTree*> views;
      for (const auto& t : r.trees) views.push_back(t.get());
      const auto m = ort::client::merge_shard_trees(views, depth);
      merged = (m->size() == whole->size() && *m == *whole) ? "identical" : "DIFFERS";
    }
    std::printf("%6d %12.2f %14.2f %14.2f %12.0f %12.2f %12.2f %11.1f%% %14.1f %10s %14.2f\n", sizes[s], cut, upd_max,
                upd_sum / n / double(kept_shards), vox / n, walk_max, walk_sum / n / double(kept_shards), 100 * kept,
                1000.0 / (decode_ms / n + walk_max + cut + upd_max), merged.c_str(), imbalance);
  }
  return 0;
}
