// octomap-rt-octree-bench: times the octree stage alone. The voxel lists of each scan are
// shot once with the cpu back end (OctoMap's own ray walk); then OctoMap's loop of
// updateNode(key, occupied, lazy_eval = false) and the batched stage build the map from the
// same lists, several times, alternating, and the best time of each is compared. Every
// batched map is checked against OctoMap's (operator==: every node, value and the count).
//
// The lists are applied `--passes` times in a row: the first pass makes the map (mostly new
// nodes), the later ones update a map that exists (saturated voxels, pruned free space),
// which is what a long mapping run mostly does.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <sys/resource.h>

#include <octomap/OcTree.h>
#include <CLI/CLI.hpp>

#include "core/backend_kind.h"
#include "core/clock.h"
#include "engine/map_engine.h"
#include "octree/batched/batched_update.h"
#include "octree/batched/morton_order.h"
#include "octree/batched/voxel_buckets.h"
#include "octree/worker_pool.h"
#include "scene/scan_set.h"

namespace {

using ort::ms_since;
using ort::SteadyClock;

struct DataSet {
  std::string name;
  std::vector<ort::VoxelList> lists;
  size_t voxels = 0;
};

DataSet shoot_lists(const std::string& path, double resolution, ort::BackendKind backend) {
  const ort::ScanSet set = ort::load_scan_graph(path);
  ort::EngineOptions opts;
  opts.resolution = resolution;
  opts.backend.kind = backend;
  ort::MapEngine engine(opts);
  DataSet d;
  d.name = path.substr(path.find_last_of('/') + 1);
  for (const ort::PosedScan& scan : set.scans) {
    const octomap::Pointcloud world = ort::world_points(scan);
    ort::ShotScan shot;
    engine.shoot(ort::sensor_origin(scan), std::span<const octomap::point3d>(&world[0], world.size()), -1.0, shot);
    d.voxels += shot.voxels.size();
    d.lists.push_back(std::move(shot.voxels));
  }
  return d;
}

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

struct Timing {
  double best_ms = 1e300;
  ort::BatchedUpdateStats stats;  // summed over the lists of the best run
  // The first run builds its tree in memory the process never touched before (later runs
  // mostly reuse what the allocator kept of the trees before them): its time, page faults and
  // kernel time (zeroing the pages) are the figures of a map that grows into new memory.
  double first_ms = 0;
  long first_faults = 0;
  double first_sys_ms = 0;
};

struct ProcessTimes {
  long minor_faults = 0;
  double sys_ms = 0;
};

ProcessTimes process_times() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return {u.ru_minflt, u.ru_stime.tv_sec * 1e3 + u.ru_stime.tv_usec * 1e-3};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Octree stage benchmark: batched stage vs OctoMap's updateNode loop on the same voxel lists"};
  std::string data_dir = OCTOMAP_RT_DATA_DIR;
  std::vector<std::string> graphs{"3dtk_dat/3dtk_3scans.graph", "octomap_share/scan_dat.graph"};
  std::vector<unsigned> threads;
  double resolution = 0.1;
  int repeat = 5, passes = 3;
  bool batched_only = false;
  std::string backend_name = "cpu";
  app.add_option("--data", data_dir, "data folder")->capture_default_str();
  app.add_option("--graph", graphs, "ScanGraph files below the data folder")->capture_default_str();
  app.add_option("--threads", threads, "thread counts of the batched stage (default: 1, 2, ..., hardware)");
  app.add_option("-r,--resolution", resolution, "voxel size [m]")->capture_default_str();
  app.add_option("--repeat", repeat, "runs of each, best taken")->capture_default_str();
  app.add_option("--passes", passes, "times the scan lists are applied in a row per run")->capture_default_str();
  app.add_flag("--batched-only", batched_only,
               "run only the batched stage (no OctoMap loop, no map check, no ordering comparison): for profilers");
  app.add_option("--backend", backend_name,
                 "back end that shoots the lists (the same voxels from each; cpu-grid is quicker on large scans)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  ort::BackendKind backend = ort::BackendKind::kCpu;
  if (!ort::parse_backend(backend_name, backend)) {
    std::fprintf(stderr, "unknown back end %s\n", backend_name.c_str());
    return 2;
  }

  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  if (threads.empty()) {
    for (unsigned t = 1; t < hw; t *= 2) threads.push_back(t);
    threads.push_back(hw);
  }
  std::printf("octree stage benchmark: %u hardware threads, %s\n", hw, cpu_model().c_str());
  std::printf("resolution %.3g m, %d pass(es) over each data set's lists, best of %d runs\n\n", resolution, passes,
              repeat);

  // The worker pool's hand-over alone: a scan's update is five jobs on the pool, each
  // started and joined (worker_pool.h), so this times an empty job per thread count: one
  // every thread runs (run) and one shared out (run_shared: threads not there in time skip it).
  for (unsigned t : threads) {
    if (t < 2) continue;
    ort::WorkerPool pool(t);
    constexpr int kJobs = 2000;
    auto start = SteadyClock::now();
    for (int j = 0; j < kJobs; ++j) pool.run([](unsigned) {});
    const double all_us = ms_since(start) * 1e3 / kJobs;
    start = SteadyClock::now();
    for (int j = 0; j < kJobs; ++j) pool.run_shared([](unsigned) {});
    std::printf("worker pool, %2u threads: %.1f us per empty job (start and join), %.1f us shared\n", t, all_us,
                ms_since(start) * 1e3 / kJobs);
  }
  std::printf("\n");

  int failures = 0;
  for (const std::string& g : graphs) {
    const DataSet d = shoot_lists(data_dir + "/" + g, resolution, backend);
    std::printf("%s: %zu scans, %zu voxel updates per pass\n", d.name.c_str(), d.lists.size(), d.voxels);

    // Ordering alone: the stage's bucketing plus a sort of every bucket on 1 thread, and the
    // bucketing on all threads, against std::sort of the whole list's Morton codes.
    if (!batched_only) {
      std::vector<ort::SortedVoxel> codes, tmp;
      ort::VoxelBuckets buckets;
      ort::BucketScratch scratch;
      ort::WorkerPool pool(hw);
      double one = 1e300, standard = 1e300, bucket_all = 1e300;
      for (int r = 0; r < repeat; ++r) {
        auto t = SteadyClock::now();
        for (const auto& l : d.lists) {
          ort::bucket_voxels(l, ort::BucketOptions{}, nullptr, buckets, scratch);
          for (size_t b = 0; b < buckets.count(); ++b) ort::sort_bucket(buckets.bucket(b), tmp);
        }
        one = std::min(one, ms_since(t));
        t = SteadyClock::now();
        for (const auto& l : d.lists) ort::bucket_voxels(l, ort::BucketOptions{}, &pool, buckets, scratch);
        bucket_all = std::min(bucket_all, ms_since(t));
        t = SteadyClock::now();
        for (const auto& l : d.lists) {
          codes.clear();
          for (const ort::VoxelUpdate& u : l) codes.push_back(ort::make_sorted_voxel(u));
          std::sort(codes.begin(), codes.end());
        }
        standard = std::min(standard, ms_since(t));
      }
      std::printf(
          "  Morton order per pass: std::sort %.2f ms; buckets + bucket sorts, 1 thread %.2f ms (%.1fx, "
          "%.1f ns/voxel); bucketing alone on %u threads %.2f ms\n",
          standard, one, standard / one, one * 1e6 / double(d.voxels), hw, bucket_all);
    }

    std::vector<std::unique_ptr<ort::BatchedOctreeUpdater>> batched;
    for (unsigned t : threads) {
      ort::BatchedUpdateOptions o;
      o.threads = t;
      batched.push_back(std::make_unique<ort::BatchedOctreeUpdater>(o));
    }
    Timing octomap_time;
    std::vector<Timing> batched_time(threads.size());
    size_t nodes = 0;
    for (int r = 0; r < repeat; ++r) {
      octomap::OcTree reference(resolution);
      auto t = SteadyClock::now();
      if (!batched_only) {
        for (int p = 0; p < passes; ++p)
          for (const auto& l : d.lists) ort::apply_updates_sequential(reference, l);
        octomap_time.best_ms = std::min(octomap_time.best_ms, ms_since(t));
        nodes = reference.size();
      }
      for (size_t i = 0; i < threads.size(); ++i) {
        octomap::OcTree tree(resolution);
        ort::BatchedUpdateStats sum, one;
        const ProcessTimes before = process_times();
        t = SteadyClock::now();
        for (int p = 0; p < passes; ++p)
          for (const auto& l : d.lists) {
            batched[i]->apply(tree, l, &one);
            sum.bucket_ms += one.bucket_ms;
            sum.top_ms += one.top_ms;
            sum.subtrees_ms += one.subtrees_ms;
            sum.sort_cpu_ms += one.sort_cpu_ms;
            sum.bucket_depth = one.bucket_depth;
            sum.subtrees += one.subtrees;
            sum.node_count_change += one.node_count_change;
          }
        const double ms = ms_since(t);
        const ProcessTimes after = process_times();
        Timing& bt = batched_time[i];
        if (r == 0) bt = Timing{ms, sum, ms, after.minor_faults - before.minor_faults, after.sys_ms - before.sys_ms};
        if (ms < bt.best_ms) {
          bt.best_ms = ms;
          bt.stats = sum;
        }
        if (batched_only) {
          nodes = tree.size();
        } else if (!(tree == reference)) {
          std::printf("  MISMATCH: batched map with %u threads differs from OctoMap's\n", threads[i]);
          ++failures;
        }
      }
    }
    const double passes_voxels = double(d.voxels) * passes;
    if (batched_only)
      std::printf("  OctoMap updateNode loop: not run (--batched-only; ratios below are meaningless), %zu nodes\n",
                  nodes);
    else
      std::printf("  OctoMap updateNode loop: %9.1f ms  (%.0f ns/voxel), %zu nodes\n", octomap_time.best_ms,
                  octomap_time.best_ms * 1e6 / passes_voxels, nodes);
    for (size_t i = 0; i < threads.size(); ++i) {
      const Timing& b = batched_time[i];
      std::printf(
          "  batched, %2u thread(s):   %9.1f ms  (%.0f ns/voxel)  %6.1fx   [buckets %.1f, top %.1f, "
          "subtrees %.1f (of which bucket sorts %.1f thread-ms) ms; %zu buckets at depth %u, %lld nodes "
          "counted in]\n",
          threads[i], b.best_ms, b.best_ms * 1e6 / passes_voxels, batched_only ? 0.0 : octomap_time.best_ms / b.best_ms,
          b.stats.bucket_ms, b.stats.top_ms, b.stats.subtrees_ms, b.stats.sort_cpu_ms, b.stats.subtrees,
          b.stats.bucket_depth, b.stats.node_count_change);
      std::printf("      first run (fresh memory): %9.1f ms, %ld page faults, %.1f ms in the kernel\n", b.first_ms,
                  b.first_faults, b.first_sys_ms);
    }
    std::printf("\n");
  }
  return failures == 0 ? 0 : 1;
}
