#include "reference_timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

#include "core/clock.h"
#include "core/errors.h"
#include "distance/distance_queries.h"
#include "distance/squared_edt.h"
#include "gpu/distance_transform.h"

#ifdef OCTOMAP_RT_HAVE_DYNAMICEDT
#include "scene/dynamic_edt_reference.h"
#endif

namespace ort::bench {
namespace {

template <class F>
double median_ms(int reps, F&& f) {
  f();  // untimed: first-touch pages, pipelines
  std::vector<double> ms;
  for (int r = 0; r < std::max(1, reps); ++r) {
    const auto t0 = SteadyClock::now();
    f();
    ms.push_back(ms_since(t0));
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

#ifdef OCTOMAP_RT_HAVE_DYNAMICEDT
// DynamicEDTOctomap over our padded grid, as the test does.
std::unique_ptr<DynamicEDTOctomap> dynamic_edt(octomap::OcTree& tree, const distance::BoxRead& read,
                                               const distance::DistanceOptions& opt) {
  const auto& g = read.grid.box;
  return scene::dynamic_edt_over(tree, g.key_lo, {g.dims.nx, g.dims.ny, g.dims.nz}, opt.max_distance,
                                 opt.unknown == distance::UnknownAs::kOccupied);
}

// The squared distance (cells) from padded cell (i, j, k) to the nearest obstacle of the grid
// within `radius` cells a side: the definition, searched cell by cell.
int64_t brute_force(const distance::OccupancyGrid& g, int i, int j, int k, int radius) {
  const auto& d = g.box.dims;
  int64_t best = -1;
  for (int z = std::max(0, k - radius); z <= std::min(d.nz - 1, k + radius); ++z)
    for (int y = std::max(0, j - radius); y <= std::min(d.ny - 1, j + radius); ++y)
      for (int x = std::max(0, i - radius); x <= std::min(d.nx - 1, i + radius); ++x)
        if (g.occupied[(size_t(z) * d.ny + y) * d.nx + x]) {
          const int64_t s = int64_t(x - i) * (x - i) + int64_t(y - j) * (y - j) + int64_t(z - k) * (z - k);
          if (best < 0 || s < best) best = s;
        }
  return best;
}

void count_differences(const octomap::OcTree& tree, DynamicEDTOctomap& edt, const distance::BoxRead& read,
                       const distance::BoxDistances& ours, const distance::DistanceOptions& opt, ReferenceTimes& t) {
  const double res = tree.getResolution();
  const double clamp_sq = (opt.max_distance / res) * (opt.max_distance / res);
  const auto& d = ours.cells.dims;
  t.dynamic_edt_differ = t.differ_ours_brute = t.differ_theirs_larger = 0;
  size_t c = 0;
  for (int k = 0; k < d.nz; ++k)
    for (int j = 0; j < d.ny; ++j)
      for (int i = 0; i < d.nx; ++i, ++c) {
        const int64_t theirs = edt.getSquaredDistanceInCells(scene::voxel_centre(tree, ours.cells.key_lo, i, j, k));
        const uint32_t mine = ours.squared[c];
        if (mine == distance::kNoObstacle || double(mine) > clamp_sq || theirs == int64_t(mine)) continue;
        ++t.dynamic_edt_differ;
        const int radius = int(std::ceil(std::sqrt(double(std::max<int64_t>(mine, theirs))))) + 1;
        const auto& lo = read.grid.box.key_lo;  // the padded grid's first cell, in keys
        const int64_t brute =
            brute_force(read.grid, int(ours.cells.key_lo[0] - lo[0] + i), int(ours.cells.key_lo[1] - lo[1] + j),
                        int(ours.cells.key_lo[2] - lo[2] + k), radius);
        t.differ_ours_brute += brute == int64_t(mine);
        t.differ_theirs_larger += theirs > int64_t(mine);
        if (t.dynamic_edt_differ <= 4)
          t.differ_examples += "(" + std::to_string(i) + "," + std::to_string(j) + "," + std::to_string(k) + ") " +
                               std::to_string(mine) + " " + std::to_string(theirs) + " " + std::to_string(brute) + "; ";
      }
}
#endif

}  // namespace

ReferenceTimes time_reference(const octomap::OcTree& tree, const double lo[3], const double hi[3],
                              const distance::DistanceOptions& opt, int threads, int reps, bool vulkan) {
  ReferenceTimes t;
  distance::DistanceLimits lim;
  lim.max_grid_cells = int64_t(1) << 40, lim.max_box_cells = int64_t(1) << 40;  // the bench sizes the box itself
  t.read_ms = median_ms(reps, [&] { (void)distance::read_box(tree, lo, hi, opt, lim); });
  const distance::BoxRead read = distance::read_box(tree, lo, hi, opt, lim);
  t.box_cells = read.cells.dims.cells();
  t.padded_cells = read.grid.box.dims.cells();
  t.cpu_threads = std::max(1, threads);
  const distance::SquaredEdt cpu = distance::cpu_edt(t.cpu_threads);
  t.cpu_edt_ms = median_ms(reps, [&] { (void)distance::answer_box(read, cpu, false); });
  if (vulkan) {
    try {
      auto gpu = std::make_shared<gpu::DistanceTransform>();
      t.vulkan_device = gpu->device_name();
      const distance::SquaredEdt on_gpu = [gpu](std::span<const uint8_t> occ, distance::GridDims d,
                                                std::span<uint32_t> out) { gpu->run(occ, d.nx, d.ny, d.nz, out); };
      t.vulkan_edt_ms = median_ms(reps, [&] { (void)distance::answer_box(read, on_gpu, false); });
    } catch (const Unsupported& e) {
      t.vulkan_device = std::string("none: ") + e.what();
    }
  }
#ifdef OCTOMAP_RT_HAVE_DYNAMICEDT
  octomap::OcTree copy(tree);
  t.dynamic_edt_ms = median_ms(reps, [&] { (void)dynamic_edt(copy, read, opt); });
  const auto edt = dynamic_edt(copy, read, opt);
  count_differences(copy, *edt, read, distance::answer_box(read, cpu, false), opt, t);
#endif
  return t;
}

}  // namespace ort::bench
