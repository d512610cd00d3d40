// CPU time of one thread for the CPU preparation of a scan graph (skt01.graph: `octomap-rt-scenegen skt-corridor --scan-scale 0.1`):
// the map-frame transform, prepare_scan and the work estimate (ray_walk_keys ray by ray, or batch_walk_keys with NEWWK=1),
// least of N repeats. Built against server/core of each version:
//   g++ -std=c++20 -O2 -g -I$S prep_harness.cpp $S/core/prepare_scan.cpp $S/core/ray_tiles.cpp $S/core/ray_space.cpp [$S/core/map_frame.cpp] -loctomap -loctomath -lpthread
// (the "before" copy without the NEWWK branch).
#include <octomap/ScanGraph.h>
#include <algorithm>
#include <cstdio>
#include <ctime>
#include "core/map_frame.h"
#include "core/prepare_scan.h"
#include "core/ray_tiles.h"
using namespace ort;
static double cpu_ms() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}
int main(int argc, char** argv) {
  octomap::ScanGraph g;
  g.readBinary(argv[1]);
  int reps = argc > 2 ? atoi(argv[2]) : 3;
  std::vector<octomap::Pointcloud> clouds;
  for (auto* n : g) clouds.emplace_back(*n->scan);
  double bt = 1e18, bp = 1e18, bw = 1e18;
  uint64_t sum = 0, rays = 0;
  for (int r = 0; r < reps; ++r) {
    double tt = 0, tp = 0, tw = 0;
    sum = 0;
    rays = 0;
    size_t i = 0;
    for (auto* n : g) {
      octomap::Pointcloud pc = clouds[i++];
      double c0 = cpu_ms();
      transform_to_map_frame(pc, n->pose, 1);
      double c1 = cpu_ms();
      PrepareReport rep;
      RayBatch b = prepare_scan(n->pose.trans(), std::span<const octomap::point3d>(&pc[0], pc.size()), -1, 0.1, rep, 1);
      double c2 = cpu_ms();
      uint64_t longest = 0;
      if (getenv("NEWWK")) {
        auto t = batch_walk_keys(b);
        sum += t.sum;
        longest = t.longest;
      } else
        for (auto& e : b.ends) {
          uint64_t k = ray_walk_keys(b, e);
          longest = std::max(longest, k);
          sum += k;
        }
      double c3 = cpu_ms();
      tt += c1 - c0;
      tp += c2 - c1;
      tw += c3 - c2;
      rays += b.ends.size();
      sum += longest;
    }
    bt = std::min(bt, tt);
    bp = std::min(bp, tp);
    bw = std::min(bw, tw);
  }
  printf("rays %llu transform %.1f prepare_scan %.1f walk_keys %.1f ms (cpu, 1 thread) sum %llu\n",
         (unsigned long long)rays, bt, bp, bw, (unsigned long long)sum);
}
