// micro harness: per scan prepare (1 thread) then shoot N times with cpu-grid, report ms + hash
#include <chrono>
#include <ctime>
static double cpu_ms() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}
#include <octomap/ScanGraph.h>
#include <algorithm>
#include <cstdio>
#include "core/cpu_grid_backend.h"
#include "core/map_frame.h"
#include "core/prepare_scan.h"
using namespace ort;
int main(int argc, char** argv) {
  octomap::ScanGraph g;
  g.readBinary(argv[1]);
  unsigned threads = argc > 2 ? atoi(argv[2]) : 1;
  int reps = argc > 3 ? atoi(argv[3]) : 3;
  auto be = make_cpu_grid_backend({0.1, 0, threads});
  std::vector<RayBatch> batches;
  double prep = 0;
  std::vector<octomap::Pointcloud> clouds;
  for (auto* n : g) {
    clouds.emplace_back(*n->scan);
    transform_to_map_frame(clouds.back(), n->pose, 1);
  }
  prep = 1e18;
  for (int r = 0; r < reps; ++r) {
    batches.clear();
    double c0 = cpu_ms();
    size_t i = 0;
    for (auto* n : g) {
      octomap::Pointcloud& pc = clouds[i++];
      PrepareReport rep;
      batches.push_back(
          prepare_scan(n->pose.trans(), std::span<const octomap::point3d>(&pc[0], pc.size()), -1, 0.1, rep, threads));
    }
    prep = std::min(prep, cpu_ms() - c0);
  }
  double best = 1e18, bshoot = 0, bcomp = 0, bcpu = 1e18;
  uint64_t h = 0, nv = 0;
  for (int r = 0; r < reps; ++r) {
    double shoot = 0, comp = 0;
    h = 0;
    nv = 0;
    auto t0 = std::chrono::steady_clock::now();
    double c0 = cpu_ms();
    for (auto& b : batches) {
      VoxelList out;
      ShootStats st;
      be->shoot(b, Traversal::kOctomap, out, st);
      shoot += st.times.shoot_ms;
      comp += st.times.compact_ms;
      for (auto& v : out) {
        uint64_t k = (uint64_t(v.x) | uint64_t(v.y) << 16 | uint64_t(v.z) << 32 | uint64_t(v.state) << 48);
        h += k * 0x9E3779B97F4A7C15ull ^ (k >> 7);
      }
      nv += out.size();
    }
    double tot = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    bcpu = std::min(bcpu, cpu_ms() - c0);
    if (tot < best) {
      best = tot;
      bshoot = shoot;
      bcomp = comp;
    }
  }
  printf("cpu %.1f ms  prep(cpu) %.1f ms  best total %.1f ms (shoot %.1f compact %.1f)  voxels %llu hash %016llx\n",
         bcpu, prep, best, bshoot, bcomp, (unsigned long long)nv, (unsigned long long)h);
}
