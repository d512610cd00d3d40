// octomap-rt-rt-bench: sweeps the rt back end's BLAS block size k and the resolution over
// real scans, and measures in the same run, on the same prepared rays:
//   - rt: BVH build time (host wall clock and GPU time), BLAS + TLAS GPU memory, and the
//     shoot time per scan (upload + trace + compaction/readback, median of --reps passes
//     after one warm-up pass);
//   - vulkan (compute back end) in exact mode on the same scans, same statistic;
//   - OctoMap's computeUpdate (its own ray walk + KeySets, one CPU thread), for scale.
// rt's voxel lists are checked against vulkan's on every scan (the bench refuses to print a
// time for a back end that gives a different answer).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <octomap/OcTree.h>
#include <CLI/CLI.hpp>

#include "core/clock.h"
#include "core/prepare_scan.h"
#include "core/ray_backend.h"
#include "engine/backend_factory.h"
#include "gpu/rt/rt_ray_backend.h"
#include "scene/scan_set.h"

namespace {

std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n') c = ' ';
  return s;
}

using ort::ms_since;
using ort::SteadyClock;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

struct Scan {
  octomap::point3d origin;
  octomap::Pointcloud world;
  ort::RayBatch batch;
};

struct Timing {
  double per_scan_ms = 0;  // median over passes of (sum over scans) / scans
  double trace_ms = 0;     // the shoot stage alone (GPU timestamps where the back end has them)
  double windows = 0;      // per scan
  bool equal = true;
  std::vector<ort::VoxelList> lists;  // of the last pass, sorted
};

void sort_list(ort::VoxelList& l) {
  std::sort(l.begin(), l.end(), [](const ort::VoxelUpdate& a, const ort::VoxelUpdate& b) {
    return std::tie(a.z, a.y, a.x) < std::tie(b.z, b.y, b.x);
  });
}

bool same(const ort::VoxelList& a, const ort::VoxelList& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].x != b[i].x || a[i].y != b[i].y || a[i].z != b[i].z || a[i].state != b[i].state) return false;
  return true;
}

Timing run(ort::RayBackend& backend, const std::vector<Scan>& scans, int reps) {
  Timing t;
  std::vector<double> pass_ms, pass_trace;
  for (int rep = -1; rep < reps; ++rep) {  // rep -1: warm-up
    double total = 0, trace = 0, windows = 0;
    t.lists.assign(scans.size(), {});
    for (size_t i = 0; i < scans.size(); ++i) {
      ort::ShootStats st;
      backend.shoot(scans[i].batch, ort::Traversal::kExact, t.lists[i], st);
      total += st.times.upload_ms + st.times.shoot_ms + st.times.compact_ms;
      trace += st.times.shoot_ms;
      windows += double(st.windows);
    }
    if (rep >= 0) {
      pass_ms.push_back(total / double(scans.size()));
      pass_trace.push_back(trace / double(scans.size()));
      t.windows = windows / double(scans.size());
    }
  }
  for (auto& l : t.lists) sort_list(l);
  t.per_scan_ms = median(pass_ms);
  t.trace_ms = median(pass_trace);
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rt back end sweep (Table III analogue): BLAS block size x resolution, against vulkan"};
  std::vector<std::string> inputs;
  std::vector<double> resolutions = {0.1, 0.2, 0.4, 0.8};
  std::vector<int> blocks = {2, 4, 8};
  int reps = 5;
  double max_range = -1.0;
  std::string device;
  bool with_octomap = true;
  app.add_option("inputs", inputs, "OctoMap .graph scan sets (all scans of each are used)")->required();
  app.add_option("-r,--resolutions", resolutions, "voxel sizes [m]")->capture_default_str();
  app.add_option("-k,--blocks", blocks, "BLAS block sizes k (2..8)")->capture_default_str();
  app.add_option("--reps", reps, "timed passes over the scans after one warm-up")->capture_default_str();
  app.add_option("--max-range", max_range, "cut rays longer than this [m]; < 0: no limit")->capture_default_str();
  app.add_option("--device", device, "Vulkan device: name substring or index");
  app.add_flag("!--no-octomap", with_octomap, "skip OctoMap's computeUpdate timing");
  CLI11_PARSE(app, argc, argv);

  std::vector<ort::ScanSet> sets;
  for (const auto& path : inputs) sets.push_back(ort::load_scan_graph(path));

  std::printf(
      "| data | res [m] | back end | k | shared space [voxels] | TLAS instances | windows/scan | "
      "BVH build host / GPU [ms] | BLAS + TLAS [MB] | ms/scan (shoot only) | vs vulkan | OctoMap ms/scan |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::string device_name;
  for (const ort::ScanSet& set : sets) {
    for (const double res : resolutions) {
      std::vector<Scan> scans;
      ort::KeyBox extent_union;
      int extent[3] = {0, 0, 0};
      uint64_t rays = 0;
      for (const ort::PosedScan& ps : set.scans) {
        Scan s;
        s.origin = ort::sensor_origin(ps);
        s.world = ort::world_points(ps);
        const std::vector<octomap::point3d> pts(s.world.begin(), s.world.end());
        ort::PrepareReport report;
        s.batch = ort::prepare_scan(s.origin, pts, max_range, res, report);
        if (!report.origin_ok) continue;
        rays += s.batch.ends.size();
        // The block grid covers the largest scan (paper IV-B: sized from the sensor's
        // local extent), plus the one-voxel window margin on each side.
        for (int i = 0; i < 3; ++i) extent[i] = std::max(extent[i], s.batch.keys.hi[i] - s.batch.keys.lo[i] + 3);
        scans.push_back(std::move(s));
      }
      if (scans.empty()) continue;
      const std::string name = set.name + " (" + std::to_string(scans.size()) + " scans, " +
                               std::to_string(rays / scans.size()) + " rays/scan)";

      double octomap_ms = 0;
      if (with_octomap) {
        octomap::OcTree tree(res);
        std::vector<double> per;
        for (int rep = 0; rep < std::max(1, std::min(reps, 3)); ++rep) {
          double total = 0;
          for (const Scan& s : scans) {
            octomap::KeySet free_cells, occupied_cells;
            const auto t0 = SteadyClock::now();
            tree.computeUpdate(s.world, s.origin, free_cells, occupied_cells, max_range);
            total += ms_since(t0);
          }
          per.push_back(total / double(scans.size()));
        }
        octomap_ms = median(per);
      }

      ort::BackendOptions vo;
      vo.kind = ort::BackendKind::kVulkan;
      vo.traversal = ort::Traversal::kExact;
      vo.resolution = res;
      vo.max_range = max_range;
      vo.device = device;
      Timing vk;
      bool have_vk = true;
      try {
        auto vulkan = ort::make_backend(vo);
        device_name = vulkan->device_name();
        vk = run(*vulkan, scans, reps);
        std::printf("| %s | %.1f | vulkan | - | - | - | %.2f | - | - | %.3f (%.3f) | 1.00 | %.1f |\n", name.c_str(),
                    res, vk.windows, vk.per_scan_ms, vk.trace_ms, octomap_ms);
      } catch (const std::exception& e) {
        have_vk = false;
        std::printf("| %s | %.1f | vulkan | unavailable: %s |\n", name.c_str(), res, one_line(e.what()).c_str());
      }
      std::fflush(stdout);

      for (const int k : blocks) {
        ort::rt::RtOptions ro;
        ro.block = k;
        for (int i = 0; i < 3; ++i) ro.wanted[i] = extent[i];
        ort::rt::RtBvhInfo info;
        ort::BackendOptions bo = vo;
        bo.kind = ort::BackendKind::kRt;
        try {
          auto rt = ort::rt::make_rt_backend(bo, ro, ort::Log{}, &info);
          Timing t = run(*rt, scans, reps);
          bool equal = true;
          if (have_vk)
            for (size_t i = 0; i < scans.size(); ++i) equal = equal && same(t.lists[i], vk.lists[i]);
          if (!equal) {
            std::printf("| %s | %.1f | rt | %d | DIFFERENT VOXELS FROM VULKAN: no time reported |\n", name.c_str(), res,
                        k);
            continue;
          }
          std::printf(
              "| %s | %.1f | rt | %d | %dx%dx%d | %llu | %.2f | %.1f / %.1f | %.3f + %.2f | %.3f (%.3f) | %s | %.1f |\n",
              name.c_str(), res, k, info.block_grid.voxels(0), info.block_grid.voxels(1), info.block_grid.voxels(2),
              (unsigned long long)info.block_grid.instance_count(), t.windows, info.build_ms, info.gpu_build_ms,
              double(info.blas_bytes) / (1024.0 * 1024.0), double(info.tlas_bytes) / (1024.0 * 1024.0), t.per_scan_ms,
              t.trace_ms, have_vk ? (std::to_string(t.per_scan_ms / vk.per_scan_ms).substr(0, 5) + "x").c_str() : "-",
              octomap_ms);
        } catch (const std::exception& e) {
          std::printf("| %s | %.1f | rt | %d | unavailable: %s |\n", name.c_str(), res, k, one_line(e.what()).c_str());
        }
        std::fflush(stdout);
      }
    }
  }
  std::printf("\ndevice: %s; times: median of %d passes after a warm-up; 'vs vulkan' = rt ms/scan / vulkan ms/scan\n",
              device_name.c_str(), reps);
  return 0;
}
