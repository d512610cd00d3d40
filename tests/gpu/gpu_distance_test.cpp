// The Vulkan distance transform gives the CPU one's integers, bit for bit: random grids of
// every shape (lines of one cell, lines longer than a workgroup, empty and full grids) and
// the padded grids of real-map boxes, through the distance queries. Skips where there is no
// Vulkan device.
#include <gtest/gtest.h>

#include <random>

#include "core/errors.h"
#include "distance/distance_queries.h"
#include "distance/squared_edt.h"
#include "gpu/distance_transform.h"
#include "query/query_test_maps.h"

namespace ort::test {
namespace {

std::unique_ptr<gpu::DistanceTransform> make_gpu() {
  try {
    const char* dev = std::getenv("OCTOMAP_RT_TEST_DEVICE");
    return std::make_unique<gpu::DistanceTransform>(dev ? dev : "");
  } catch (const Unsupported& e) {
    return nullptr;
  }
}

TEST(GpuDistance, SameIntegersAsTheCpuOnRandomGrids) {
  auto gpu = make_gpu();
  if (!gpu) GTEST_SKIP() << "no Vulkan device";
  static_assert(gpu::kEdtNoObstacle == distance::kNoObstacle);
  std::mt19937 rng(5);
  const int shapes[][3] = {{1, 1, 1}, {1, 1, 70}, {70, 1, 1}, {3, 130, 2}, {33, 17, 9}, {64, 64, 64}, {200, 90, 3}};
  for (const auto& s : shapes)
    for (double density : {0.0, 0.001, 0.05, 0.5, 1.0}) {
      const distance::GridDims d{s[0], s[1], s[2]};
      std::vector<uint8_t> occ(size_t(d.cells()));
      std::bernoulli_distribution b(density);
      for (auto& o : occ) o = b(rng);
      std::vector<uint32_t> cpu(occ.size()), dev(occ.size());
      distance::squared_edt(occ, d, cpu, 2);
      gpu->run(occ, d.nx, d.ny, d.nz, dev);
      ASSERT_EQ(cpu, dev) << s[0] << "x" << s[1] << "x" << s[2] << " density " << density;
    }
}

TEST(GpuDistance, RealMapBoxesEqualTheCpuPath) {
  auto gpu = make_gpu();
  if (!gpu) GTEST_SKIP() << "no Vulkan device";
  const distance::SquaredEdt device = [&](std::span<const uint8_t> occ, distance::GridDims d, std::span<uint32_t> out) {
    gpu->run(occ, d.nx, d.ny, d.nz, out);
  };
  for (const NamedMap& map : query_test_maps()) {
    SCOPED_TRACE(map.name);
    double lo[3], hi[3];
    map_extent(*map.tree, 0, lo, hi);
    for (int m : {1, 3})
      for (auto unknown : {distance::UnknownAs::kFree, distance::UnknownAs::kOccupied}) {
        distance::DistanceOptions opt;
        opt.max_distance = 1.5, opt.cell_voxels = m, opt.unknown = unknown;
        // A 6 x 6 x 2 m box in the middle of the map.
        double blo[3], bhi[3];
        for (int a = 0; a < 3; ++a) {
          const double c = (lo[a] + hi[a]) / 2, half = a == 2 ? 1.0 : 3.0;
          blo[a] = c - half, bhi[a] = c + half;
        }
        const auto read = distance::read_box(*map.tree, blo, bhi, opt, {});
        const auto want = distance::answer_box(read, distance::cpu_edt(2), true);
        const auto got = distance::answer_box(read, device, true);
        EXPECT_EQ(got.squared, want.squared);
        EXPECT_EQ(got.gradient, want.gradient);
      }
  }
}

}  // namespace
}  // namespace ort::test
