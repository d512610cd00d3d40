// The GPU-free half of the `rt` back end, on the CPU: the block grid (BLAS
// boxes, TLAS instances and their translations, instance/primitive -> key), the key-aligned
// windows, the window frame, and a CPU model of the whole rt shoot (float candidates from
// the enlarged AABBs, then the exact double slab test) that must equal the exact CPU
// reference on rays along faces, through edges and corners, zero-length, across windows.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "core/exact_traversal.h"
#include "cpu/cpu_backend.h"
#include "gpu/rt/block_grid.h"

namespace ort::rt {
namespace {

using Key = std::array<int, 3>;

TEST(RtBlockGrid, RoundsUpToBlocksAndShrinksToLimits) {
  const int wanted[3] = {10, 17, 3};
  const BlockGrid s = choose_block_grid(4, wanted, BlockGridLimits{});
  EXPECT_EQ(s.voxels(0), 12);
  EXPECT_EQ(s.voxels(1), 20);
  EXPECT_EQ(s.voxels(2), 4);
  EXPECT_EQ(s.instance_count(), 3u * 5u * 1u);
  EXPECT_EQ(s.grid_words(), (12u * 20u * 4u + 15u) / 16u);

  BlockGridLimits tight;
  tight.max_instances = 100;
  const int big[3] = {1000, 1000, 40};
  const BlockGrid t = choose_block_grid(2, big, tight);
  EXPECT_LE(t.instance_count(), 100u);
  EXPECT_GE(t.blocks[0], 1);
  EXPECT_LE(t.blocks[2], 20);

  EXPECT_THROW(choose_block_grid(1, wanted, BlockGridLimits{}), std::invalid_argument);
  EXPECT_THROW(choose_block_grid(9, wanted, BlockGridLimits{}), std::invalid_argument);
  BlockGridLimits none;
  none.max_voxels = 7;
  EXPECT_THROW(choose_block_grid(2, wanted, none), std::invalid_argument);
}

TEST(RtBlockGrid, WantedFromRangeCoversTheRangeBothWays) {
  int w[3];
  wanted_from_range(0.1, 10.0, 512, w);
  EXPECT_EQ(w[0], 204);
  EXPECT_EQ(w[2], 204);
  wanted_from_range(0.1, -1.0, 512, w);
  EXPECT_EQ(w[1], 512);
}

TEST(RtBlockGrid, BlockAabbsAreTheVoxelsEnlargedByTheMargin) {
  for (int k = 2; k <= 8; ++k) {
    const auto boxes = block_aabbs(k);
    ASSERT_EQ(boxes.size(), size_t(k * k * k));
    for (int p = 0; p < k * k * k; ++p) {
      const int v[3] = {p % k, (p / k) % k, p / (k * k)};
      for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(boxes[p].min[i], float(v[i]) - kAabbMargin);
        EXPECT_EQ(boxes[p].max[i], float(v[i] + 1) + kAabbMargin);
      }
    }
  }
}

TEST(RtBlockGrid, InstancesAndPrimitivesNameEveryVoxelOfTheWindowOnce) {
  const int wanted[3] = {9, 6, 7};
  const BlockGrid s = choose_block_grid(3, wanted, BlockGridLimits{});
  const int lo[3] = {32760, 100, 65530};
  std::set<Key> seen;
  const uint32_t prims = uint32_t(s.block * s.block * s.block);
  for (uint64_t i = 0; i < s.instance_count(); ++i) {
    float t[3];
    instance_translation(s, i, t);
    for (uint32_t p = 0; p < prims; ++p) {
      int k[3];
      voxel_key(s, lo, i, p, k);
      const Aabb box = block_aabbs(s.block)[p];
      for (int a = 0; a < 3; ++a) {
        // The instance's box in the window frame is [key - lo, key - lo + 1] (+ margin).
        EXPECT_EQ(double(box.min[a]) + t[a], double(k[a] - lo[a]) - double(kAabbMargin));
        EXPECT_GE(k[a], lo[a]);
        EXPECT_LT(k[a], lo[a] + s.voxels(a));
      }
      EXPECT_TRUE(seen.insert({k[0], k[1], k[2]}).second);
    }
  }
  EXPECT_EQ(seen.size(), s.voxel_count());
}

TEST(RtBlockGrid, WindowsTileTheWidenedKeyBoxOnceEach) {
  const int wanted[3] = {8, 8, 4};
  const BlockGrid s = choose_block_grid(4, wanted, BlockGridLimits{});
  KeyBox keys;
  keys.lo[0] = 3;
  keys.hi[0] = 30;  // near the low key edge: clamped to 0
  keys.lo[1] = 32760;
  keys.hi[1] = 32770;
  keys.lo[2] = 65530;
  keys.hi[2] = 65535;  // at the high key edge: clamped to 65535
  const auto windows = tile_windows(keys, s, 1);
  std::map<Key, int> hits;
  for (const KeyBox& w : windows) {
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(w.hi[i] - w.lo[i] + 1, s.voxels(i));
      EXPECT_GE(w.lo[i], 0);
      EXPECT_LE(w.hi[i], 65535);
    }
    for (int x = w.lo[0]; x <= w.hi[0]; ++x)
      for (int y = w.lo[1]; y <= w.hi[1]; ++y)
        for (int z = w.lo[2]; z <= w.hi[2]; ++z) hits[{x, y, z}]++;
  }
  uint64_t expect = uint64_t(31 - 2 + 1) * (32771 - 32759 + 1) * (65535 - 65529 + 1);
  EXPECT_EQ(hits.size(), expect);
  for (const auto& [k, n] : hits) ASSERT_EQ(n, 1);
  EXPECT_EQ(hits.begin()->first[0], 2);
  EXPECT_TRUE(tile_windows(KeyBox{}, s).empty());
}

TEST(RtBlockGrid, WindowFrameIsVoxelUnitsFromTheLowKey) {
  const int lo[3] = {32768, 32700, 40000};
  const double p[3] = {0.25, -0.05, 723.2};
  float f[3];
  to_window_frame(p, 0.1, lo, f);
  EXPECT_NEAR(f[0], 2.5, 1e-5);
  EXPECT_NEAR(f[1], 67.5, 1e-5);
  EXPECT_NEAR(f[2], 7232.0 - (40000 - 32768), 1e-3);
}

// ---- CPU model of the rt shoot ----------------------------------------------------------

// What a ray-tracing implementation at least reports: float ray vs float AABB, slab test.
// Written the way fast traversal kernels write it (reciprocal direction, box * inv - o * inv,
// comparisons that fail on NaN), which is what makes exactly-zero components dangerous.
bool float_ray_hits_box(const float o[3], const float d[3], float tmax, const float lo[3], const float hi[3]) {
  float t0 = 0.0f, t1 = tmax;
  for (int i = 0; i < 3; ++i) {
    const float inv = 1.0f / d[i];
    float ta = lo[i] * inv - o[i] * inv, tb = hi[i] * inv - o[i] * inv;
    if (ta > tb) std::swap(ta, tb);
    if (!(ta <= t1) || !(tb >= t0)) return false;  // NaN: not hit
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return true;
}

TEST(RtBlockGrid, TraceDirectionHasNoZeroComponents) {
  const float o[3] = {3.0f, 5.0f, 7.0f}, f[3] = {3.0f, 9.5f, 7.0f - 1e-9f};
  float d[3];
  trace_direction(o, f, d);
  EXPECT_EQ(d[0], kMinDirection);
  EXPECT_EQ(d[1], 4.5f);
  EXPECT_EQ(d[2], kMinDirection);  // 7 - 1e-9 rounds to 7 in float
  const float g[3] = {3.0f - 1e-6f, 5.0f, 7.0f};
  trace_direction(o, g, d);
  EXPECT_EQ(d[0], -kMinDirection);  // the sign of a tiny component is kept
  // A ray in the plane y = 5 (a voxel face) meets the boxes on both sides of the face...
  const float below_lo[3] = {2.0f - kAabbMargin, 4.0f - kAabbMargin, 6.0f - kAabbMargin};
  const float below_hi[3] = {3.0f + kAabbMargin, 5.0f + kAabbMargin, 7.0f + kAabbMargin};
  const float ray_end[3] = {9.0f, 5.0f, 7.0f};
  trace_direction(o, ray_end, d);
  EXPECT_TRUE(float_ray_hits_box(o, d, 1.0f, below_lo, below_hi));
  // ...which the raw direction (zero y and z) loses to inf - inf in this arithmetic.
  const float raw[3] = {6.0f, 0.0f, 0.0f};
  EXPECT_FALSE(float_ray_hits_box(o, raw, 1.0f, below_lo, below_hi));
}

// The rt back end's algorithm, in C++: windows, float frame, enlarged AABBs as candidates,
// the exact test in map coordinates, the 2-bit states, occupied wins.
VoxelList model_rt_shoot(const RayBatch& batch, const BlockGrid& s, uint64_t* candidates = nullptr) {
  std::map<Key, uint32_t> states;
  const double res = batch.resolution, inv_res = 1.0 / res;
  const auto boxes = block_aabbs(s.block);
  const uint32_t k = uint32_t(s.block);
  const double a[3] = {batch.origin.x(), batch.origin.y(), batch.origin.z()};
  for (const KeyBox& w : tile_windows(batch.keys, s)) {
    for (const RayEnd& e : batch.ends) {
      const double b[3] = {e.x, e.y, e.z};
      float o[3], f[3], d[3];
      to_window_frame(a, res, w.lo, o);
      to_window_frame(b, res, w.lo, f);
      trace_direction(o, f, d);
      // Enumerate the voxels of this window near the float segment (the BVH's job).
      int vlo[3], vhi[3];
      for (int i = 0; i < 3; ++i) {
        vlo[i] = std::max(0, int(std::floor(std::min(o[i], f[i]))) - 1);
        vhi[i] = std::min(s.voxels(i) - 1, int(std::floor(std::max(o[i], f[i]))) + 1);
      }
      for (int z = vlo[2]; z <= vhi[2]; ++z)
        for (int y = vlo[1]; y <= vhi[1]; ++y)
          for (int x = vlo[0]; x <= vhi[0]; ++x) {
            const int v[3] = {x, y, z};  // window-local voxel
            const uint64_t inst =
                uint64_t(x / s.block) +
                uint64_t(s.blocks[0]) * (uint64_t(y / s.block) + uint64_t(s.blocks[1]) * uint64_t(z / s.block));
            const uint32_t prim = uint32_t(x % s.block) + k * (uint32_t(y % s.block) + k * uint32_t(z % s.block));
            float t[3], lo[3], hi[3];
            instance_translation(s, inst, t);
            for (int i = 0; i < 3; ++i) {
              lo[i] = boxes[prim].min[i] + t[i];
              hi[i] = boxes[prim].max[i] + t[i];
            }
            if (!float_ray_hits_box(o, d, 1.0f, lo, hi)) continue;
            if (candidates) ++*candidates;
            int key[3];
            voxel_key(s, w.lo, inst, prim, key);
            EXPECT_EQ(key[0], w.lo[0] + v[0]);
            bool inside = true;
            for (int i = 0; i < 3; ++i) inside = inside && key[i] <= w.hi[i];
            if (inside && segment_touches_voxel(a, b, key, res)) states[{key[0], key[1], key[2]}] |= 2u;
          }
      if (e.flags & kRayEndOccupied) {
        int key[3];
        bool inside = true;
        for (int i = 0; i < 3; ++i) {
          key[i] = int(std::floor(inv_res * b[i])) + kTreeMaxVal;
          inside = inside && key[i] >= w.lo[i] && key[i] <= w.hi[i];
        }
        if (inside) states[{key[0], key[1], key[2]}] |= 1u;
      }
    }
  }
  VoxelList out;
  for (const auto& [key, st] : states) {
    out.push_back(make_update(octomap::OcTreeKey(key[0], key[1], key[2]), (st & 1u) != 0));
  }
  return out;
}

const int* wanted_cube() {
  static const int w[3] = {64, 64, 64};
  return w;
}

std::vector<std::array<int, 4>> sorted(const VoxelList& l) {
  std::vector<std::array<int, 4>> v;
  for (const auto& u : l) v.push_back({u.x, u.y, u.z, u.state});
  std::sort(v.begin(), v.end());
  return v;
}

RayBatch make_batch(const octomap::point3d& origin, const std::vector<octomap::point3d>& ends, double res) {
  RayBatch b;
  b.origin = origin;
  b.resolution = res;
  octomap::OcTree t(res);
  b.origin_key = t.coordToKey(origin);
  b.keys.include(b.origin_key);
  for (size_t i = 0; i < ends.size(); ++i) {
    b.ends.push_back({ends[i].x(), ends[i].y(), ends[i].z(), i % 3 == 2 ? 0u : uint32_t(kRayEndOccupied)});
    b.keys.include(t.coordToKey(ends[i]));
  }
  return b;
}

TEST(RtBlockGrid, ModelOfTheRtShootEqualsTheExactCpuReference) {
  const double res = 0.1;
  std::mt19937 rng(2024);
  std::uniform_real_distribution<float> u(-1.2f, 1.2f);
  std::uniform_int_distribution<int> g(-12, 12);
  std::uniform_int_distribution<int> pick(0, 5);
  const int wanted[3] = {8, 12, 8};
  const BlockGrid s = choose_block_grid(4, wanted, BlockGridLimits{});  // small: many windows
  auto cpu = make_cpu_backend(res);
  uint64_t rays = 0;
  for (int scan = 0; scan < 60; ++scan) {
    octomap::point3d origin(u(rng), u(rng), u(rng));
    if (scan % 4 == 0) origin = octomap::point3d(g(rng) * 0.1f, g(rng) * 0.1f, g(rng) * 0.1f);  // a corner
    std::vector<octomap::point3d> ends;
    for (int r = 0; r < 200; ++r) {
      octomap::point3d e(u(rng), u(rng), u(rng));
      switch (pick(rng)) {
        case 0: e = octomap::point3d(g(rng) * 0.1f, g(rng) * 0.1f, g(rng) * 0.1f); break;  // grid point
        case 1: e = octomap::point3d(e.x(), origin.y(), origin.z()); break;                // axis-aligned
        case 2: e = octomap::point3d(g(rng) * 0.1f, origin.y(), e.z()); break;             // in a plane
        case 3:
          if (r % 10 == 0) e = origin;
          break;  // zero length
        default: break;
      }
      ends.push_back(e);
    }
    const RayBatch batch = make_batch(origin, ends, res);
    VoxelList want;
    ShootStats st;
    cpu->shoot(batch, Traversal::kExact, want, st);
    ASSERT_EQ(sorted(model_rt_shoot(batch, s)), sorted(want)) << "scan " << scan << " origin " << origin;
    rays += ends.size();
  }
  EXPECT_GE(rays, 12000u);
}

TEST(RtBlockGrid, ModelCoversVoxelsJustBelowTheKeyBox) {
  // Every ray lies in the planes x = -16 and y = 5 (voxel faces at 0.5 m), so the voxels on
  // their low sides have keys below the scan's key box: the window margin must hold them.
  const double res = 0.5;
  const octomap::point3d origin(-16.0f, 5.0f, 4.0f);
  const std::vector<octomap::point3d> ends = {
      {-16.0f, 5.0f, 18.1849651f}, {-16.0f, 5.0f, 4.34148407f}, {1.25694466f, 5.0f, 4.0f}, {-16.0f, 5.0f, 4.0f}};
  const RayBatch batch = make_batch(origin, ends, res);
  auto cpu = make_cpu_backend(res);
  VoxelList want;
  ShootStats st;
  cpu->shoot(batch, Traversal::kExact, want, st);
  for (int k : {2, 4, 8}) {
    const int wanted[3] = {64, 64, 64};
    EXPECT_EQ(sorted(model_rt_shoot(batch, choose_block_grid(k, wanted, BlockGridLimits{}))), sorted(want))
        << "k " << k;
  }
  const KeyBox w = tile_windows(batch.keys, choose_block_grid(4, wanted_cube(), BlockGridLimits{}))[0];
  EXPECT_EQ(w.lo[0], batch.keys.lo[0] - 1);
}

TEST(RtBlockGrid, MarginCostsFewExtraCandidates) {
  // The margin must let in touching boxes but not many more: count candidates per true voxel.
  const double res = 0.2;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  std::vector<octomap::point3d> ends;
  for (int r = 0; r < 500; ++r) ends.emplace_back(u(rng), u(rng), u(rng));
  const RayBatch batch = make_batch({0.01f, 0.02f, 0.03f}, ends, res);
  const int wanted[3] = {64, 64, 64};
  const BlockGrid s = choose_block_grid(8, wanted, BlockGridLimits{});
  uint64_t candidates = 0, touched = 0;
  model_rt_shoot(batch, s, &candidates);
  for (const RayEnd& e : batch.ends) {
    std::vector<octomap::OcTreeKey> keys;
    exact_ray_keys(batch.origin, octomap::point3d(e.x, e.y, e.z), res, keys);
    touched += keys.size();
  }
  EXPECT_GE(candidates, touched);
  EXPECT_LT(double(candidates), 1.2 * double(touched));
}

}  // namespace
}  // namespace ort::rt
