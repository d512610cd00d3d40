// The native ray walk (core/octomap_ray_walk.h) and the cpu-grid back end against
// OctoMap's own computeRayKeys and insertPointCloud, on rays chosen to hit the corner cases.
#include <cmath>
#include <random>
#include <set>
#include <tuple>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "core/octomap_ray_walk.h"
#include "core/prepare_scan.h"
#include "cpu/cpu_backend.h"
#include "cpu/cpu_grid_backend.h"

namespace ort {
namespace {

// Rays that stress OctoMap's walk: random, axis-aligned, along voxel faces, through edges and
// corners (grid coordinates), zero-length and sub-voxel, negative, near the key-range edge.
std::vector<std::pair<octomap::point3d, octomap::point3d>> tricky_rays(size_t n, double res, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-20.0f, 20.0f);
  std::uniform_int_distribution<int> g(-100, 100);
  std::uniform_int_distribution<int> kind(0, 7);
  const float edge = float(32767 * res);
  std::vector<std::pair<octomap::point3d, octomap::point3d>> rays;
  for (size_t i = 0; i < n; ++i) {
    octomap::point3d o(u(rng), u(rng), u(rng)), e(u(rng), u(rng), u(rng));
    switch (kind(rng)) {
      case 0: break;
      case 1:
        e = o;
        e(i % 3) += u(rng);
        break;  // axis-aligned
      case 2:
        o = octomap::point3d(g(rng) * res, g(rng) * res, g(rng) * res);  // corners
        e = octomap::point3d(g(rng) * res, g(rng) * res, g(rng) * res);
        break;
      case 3:
        o = octomap::point3d(g(rng) * res, u(rng), g(rng) * res);  // along faces/edges
        e = octomap::point3d(o.x(), u(rng), g(rng) * res);
        break;
      case 4: e = o + octomap::point3d(u(rng), u(rng), u(rng)) * float(res / 40); break;  // sub-voxel
      case 5: e = o; break;                                                               // zero length
      case 6:
        o = octomap::point3d(edge - 1.0f, -edge + 2.0f, u(rng));  // key-range edge
        e = octomap::point3d(edge - 0.001f * (1 + g(rng) % 5), -edge + 0.001f, u(rng));
        break;
      case 7:
        o = octomap::point3d(-u(rng) - 0.5f, -std::abs(u(rng)), -1.0f);  // negative
        e = o - octomap::point3d(std::abs(u(rng)), 0.5f, std::abs(u(rng)));
        break;
    }
    rays.push_back({o, e});
  }
  return rays;
}

TEST(OctomapRayWalk, EqualsComputeRayKeysOn100kRays) {
  for (double res : {0.1, 0.05, 0.2}) {
    octomap::OcTree tree(res);
    octomap::KeyRay ray;
    size_t checked = 0;
    for (const auto& [o, e] : tricky_rays(40000, res, 3)) {
      octomap::OcTreeKey ko, ke;
      if (!coord_to_key_checked(o, res, ko) || !coord_to_key_checked(e, res, ke)) continue;
      ASSERT_TRUE(tree.computeRayKeys(o, e, ray));
      std::vector<octomap::OcTreeKey> ours;
      walk_octomap_ray(o, e, ko, ke, res, [&](const octomap::OcTreeKey& k) { ours.push_back(k); });
      ASSERT_EQ(ours.size(), ray.size()) << o << " -> " << e;
      size_t j = 0;
      for (const auto& k : ray) ASSERT_TRUE(k == ours[j++]) << o << " -> " << e;
      ++checked;
    }
    EXPECT_GT(checked, 35000u);
  }
}

// Many small scans of a few rays each, so that every ray's voxels are checked.
TEST(CpuGridBackend, EqualsCpuBackendPerScan) {
  const double res = 0.1;
  auto reference = make_cpu_backend(res);
  auto grid = make_cpu_grid_backend({res, 1ull << 20, 2});  // 1 MiB: forces several windows
  const auto rays = tricky_rays(20000, res, 9);
  for (Traversal mode : {Traversal::kOctomap, Traversal::kExact}) {
    uint64_t windows = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
      // One ray per scan, so that each ray's voxels are compared; a second ray from the same
      // origin in every third scan brings occupied/free conflicts.
      std::vector<octomap::point3d> pts = {rays[i].second};
      if (i % 3 == 0) pts.push_back(rays[i].first + (rays[i].second - rays[i].first) * 0.5f);
      PrepareReport rep;
      const RayBatch b = prepare_scan(rays[i].first, pts, (i % 8) ? -1.0 : 5.0, res, rep);
      if (!rep.origin_ok) continue;
      VoxelList a, g;
      ShootStats sa, sg;
      reference->shoot(b, mode, a, sa);
      grid->shoot(b, mode, g, sg);
      windows += sg.windows;
      EXPECT_EQ(sg.words_read_back, sg.words_touched);
      auto as_set = [](const VoxelList& l) {
        std::set<std::tuple<int, int, int, int>> s;
        for (const auto& v : l) s.insert({v.x, v.y, v.z, v.state});
        return s;
      };
      ASSERT_EQ(as_set(g), as_set(a)) << "scan " << i << " mode " << to_string(mode);
      ASSERT_EQ(g.size(), a.size()) << "a key listed twice";
    }
    EXPECT_GT(windows, rays.size()) << "the small grid should have needed several windows for long rays";
  }
}

TEST(CpuGridBackend, OccupiedWinsOverFreeInOneScan) {
  const double res = 0.1;
  auto grid = make_cpu_grid_backend({res, 1ull << 20, 2});
  // Ray 1 ends in the voxel that ray 2 passes through.
  std::vector<octomap::point3d> pts = {{0.55f, 0.05f, 0.05f}, {2.05f, 0.05f, 0.05f}};
  PrepareReport rep;
  const RayBatch b = prepare_scan({0.05f, 0.05f, 0.05f}, pts, -1.0, res, rep);
  VoxelList out;
  ShootStats st;
  grid->shoot(b, Traversal::kOctomap, out, st);
  int occupied = 0, free = 0;
  for (const auto& v : out) {
    if (v.x == 32768 + 5 && v.y == 32768 && v.z == 32768) {
      EXPECT_TRUE(v.occupied());
    }
    (v.occupied() ? occupied : free)++;
  }
  EXPECT_EQ(occupied, 2);
  EXPECT_EQ(free, 19);  // voxels 0..19 along x minus the occupied one at 5
}

}  // namespace
}  // namespace ort
