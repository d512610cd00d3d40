// The AVX2 walk without the per-step window test (cpu/window_walk_avx2.h, rays_stay_inside):
// taken only where no ray can leave its row-by-row window, and there the same voxels as
// OctoMap's walk, ray by ray; refused for a window of a split ray space, a tile's window
// (rays running on beyond it) and an origin or end near a face.
#include <map>
#include <random>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "core/octomap_ray_walk.h"
#include "core/prepare_scan.h"
#include "core/ray_space.h"
#include "cpu/brick_layout.h"
#include "cpu/cpu_backend.h"
#include "cpu/cpu_grid_backend.h"
#include "cpu/grid_marker.h"
#include "cpu/window_walk_avx2.h"

namespace ort {
namespace {

constexpr double kRes = 0.1;

// A scan from `origin` of rays up to `reach` metres: random directions, along the axes and in
// the axis planes, ends on voxel borders (where rounding decides the end key).
RayBatch scan(const octomap::point3d& origin, float reach, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), len(0.0f, 1.0f);
  std::vector<octomap::point3d> pts;
  for (int i = 0; i < 8000; ++i) {
    octomap::point3d d(u(rng), u(rng), u(rng));
    if (i % 5 == 0) d(i / 5 % 3) = 0.0f;                                                      // in an axis plane
    if (i % 5 == 1) d = octomap::point3d(0, 0, 0), d(i / 5 % 3) = u(rng) < 0 ? -1.0f : 1.0f;  // along an axis
    if (d.norm() == 0.0f) continue;
    octomap::point3d e = origin + d.normalized() * (reach * len(rng));
    if (i % 4 == 0)
      e = octomap::point3d(std::round(e.x() * 10) / 10, std::round(e.y() * 10) / 10, std::round(e.z() * 10) / 10);
    pts.push_back(e);
  }
  PrepareReport rep;
  RayBatch b = prepare_scan(origin, pts, -1.0, kRes, rep);
  EXPECT_TRUE(rep.origin_ok);
  return b;
}

// Voxel states the AVX2 walk marks for rays [begin, end), against OctoMap's walk cut to the window.
struct Marks {
  std::map<std::tuple<int, int, int>, uint32_t> walked, octomap;
};
Marks walk_both(const RayBatch& b, size_t begin, size_t end, const BrickLayout& layout) {
  Marks m;
  for (size_t r = begin; r < end; ++r) {
    const RayEnd& e = b.ends[r];
    const octomap::point3d p(e.x, e.y, e.z);
    octomap::OcTreeKey end_key;
    EXPECT_TRUE(coord_to_key_checked(p, kRes, end_key));
    if (end_key != b.origin_key) {
      walk_octomap_ray(b.origin, p, b.origin_key, end_key, kRes, [&](const octomap::OcTreeKey& k) {
        if (layout.contains(k)) m.octomap[{k[0], k[1], k[2]}] |= kStateFree;
      });
    }
    if (e.flags & kRayEndOccupied) m.octomap[{end_key[0], end_key[1], end_key[2]}] |= kStateOccupied;
  }
  std::vector<uint32_t> grid(layout.voxels() / 16 + 2, 0), touched;
  GridMarker marker{grid.data(), touched, false};
  walk_rays_avx2(b, begin, end, layout, kRes, marker);
  for (uint32_t word : touched)
    for (uint32_t slot = 0; slot < 16; ++slot)
      if (const uint32_t bits = grid[word] >> (2 * slot) & 3u) {
        const octomap::OcTreeKey k = layout.key_of(word, slot);
        m.walked[{k[0], k[1], k[2]}] = bits;
      }
  return m;
}

TEST(WindowWalkStays, OneWindowOfTheWholeRaySpaceEqualsOctomapRayByRay) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  for (const octomap::point3d& origin : {octomap::point3d(0.05f, 0.05f, 0.05f), octomap::point3d(0.8f, -1.6f, 0.4f),
                                         octomap::point3d(-12.34f, 7.0f, 1.25f)}) {
    const RayBatch b = scan(origin, 4.0f, 7);
    const std::vector<KeyBox> windows = plan_windows(b.keys, 1ull << 30);
    ASSERT_EQ(windows.size(), 1u);
    const BrickLayout layout(windows[0]);
    ASSERT_TRUE(layout.rows()) << "4 m a side fits the row-by-row layout";
    ASSERT_TRUE(rays_stay_inside(b, 0, b.ends.size(), layout, kRes));
    int mismatches = 0;
    for (size_t r = 0; r < b.ends.size(); ++r) {
      const Marks m = walk_both(b, r, r + 1, layout);
      if (m.walked != m.octomap && ++mismatches <= 3) ADD_FAILURE() << "origin " << origin << " ray " << r;
    }
    EXPECT_EQ(mismatches, 0);
    const Marks all = walk_both(b, 0, b.ends.size(), layout);
    EXPECT_GT(all.octomap.size(), 10000u);
    EXPECT_EQ(all.walked, all.octomap);
  }
}

TEST(WindowWalkStays, RefusedWhereARayMayLeaveTheWindow) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  const RayBatch b = scan(octomap::point3d(0.8f, -1.6f, 0.4f), 4.0f, 8);
  // A split ray space: no window of it holds every end.
  const std::vector<KeyBox> split = plan_windows(b.keys, 64u << 10);
  ASSERT_GT(split.size(), 1u);
  for (const KeyBox& w : split) EXPECT_FALSE(rays_stay_inside(b, 0, b.ends.size(), BrickLayout(w, true), kRes));
  // A tile's window: the batch names a box that its rays run beyond (as MapEngine::shoot_tiled
  // does, in a batch that does not claim its box holds the ends).
  RayBatch tile = b;
  tile.keys_hold_ends = false;
  for (int i = 0; i < 3; ++i) tile.keys.lo[i] = b.origin_key[i] - 8, tile.keys.hi[i] = b.origin_key[i] + 8;
  EXPECT_FALSE(
      rays_stay_inside(tile, 0, tile.ends.size(), BrickLayout(plan_windows(tile.keys, 1ull << 30)[0], true), kRes));
  // The whole ray space without the margin: ends on the faces; and each margin key matters,
  // judged from the batch's box and ray by ray.
  ASSERT_TRUE(b.keys_hold_ends);
  RayBatch unknown_box = b;
  unknown_box.keys_hold_ends = false;
  for (const RayBatch* batch : std::initializer_list<const RayBatch*>{&b, &unknown_box}) {
    EXPECT_FALSE(rays_stay_inside(*batch, 0, batch->ends.size(), BrickLayout(b.keys, true), kRes));
    for (int axis = 0; axis < 3; ++axis) {
      for (int side = 0; side < 2; ++side) {
        KeyBox w = plan_windows(b.keys, 1ull << 30)[0];
        EXPECT_TRUE(rays_stay_inside(*batch, 0, batch->ends.size(), BrickLayout(w, true), kRes));
        (side ? w.hi[axis] : w.lo[axis]) += side ? -1 : 1;  // one key less of margin on one face
        EXPECT_FALSE(rays_stay_inside(*batch, 0, batch->ends.size(), BrickLayout(w, true), kRes))
            << "axis " << axis << " side " << side << " box known " << batch->keys_hold_ends;
      }
    }
  }
}

// The back end takes it on a whole scan in one row-by-row window: its voxel list is the cpu
// back end's (OctoMap's computeRayKeys), on one thread and on two.
TEST(WindowWalkStays, CpuGridOnAScanInOneRowWindowEqualsCpuBackend) {
  auto reference = make_cpu_backend(kRes);
  for (unsigned threads : {1u, 2u}) {
    auto grid = make_cpu_grid_backend({kRes, 0, threads});
    for (uint32_t seed = 1; seed <= 3; ++seed) {
      const RayBatch b = scan(octomap::point3d(0.05f * float(seed), -0.35f, 0.8f), 4.5f, seed);
      VoxelList a, g;
      ShootStats sa, sg;
      reference->shoot(b, Traversal::kOctomap, a, sa);
      grid->shoot(b, Traversal::kOctomap, g, sg);
      EXPECT_EQ(sg.windows, 1u);
      std::set<std::tuple<int, int, int, int>> sa_set, sg_set;
      for (const auto& v : a) sa_set.insert({v.x, v.y, v.z, v.state});
      for (const auto& v : g) sg_set.insert({v.x, v.y, v.z, v.state});
      ASSERT_EQ(sg_set, sa_set) << "threads " << threads << " seed " << seed;
      ASSERT_EQ(g.size(), a.size()) << "a key listed twice";
    }
  }
}

}  // namespace
}  // namespace ort
