// The cpu-grid back end's bricked layout (cpu/brick_layout.h) and its window walk (the voxel
// index kept per axis, the window's bounds tested only on the stepping axis) against the cpu
// back end (OctoMap's computeRayKeys + a hash set), on whole scans: rays along each axis, in
// the axis planes, across brick and window borders, at the key range's edges, one thread
// (plain stores) and two (atomic OR), scalar and AVX2.
#include <map>
#include <random>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "core/octomap_ray_walk.h"
#include "core/prepare_scan.h"
#include "cpu/brick_layout.h"
#include "cpu/cpu_backend.h"
#include "cpu/cpu_grid_backend.h"
#include "cpu/grid_marker.h"
#include "cpu/window_walk_avx2.h"

namespace ort {
namespace {

// Both layouts: bricks, and rows of whole words (the default for windows up to kRowsUpTo voxels).
TEST(BrickLayout, IndexIsABijectionAndKeyOfInvertsIt) {
  KeyBox w;
  w.lo[0] = 5, w.lo[1] = 1000, w.lo[2] = 65520;
  w.hi[0] = 5 + 20, w.hi[1] = 1000 + 8, w.hi[2] = 65535;  // 21 x 9 x 16: partial bricks in x and y, rows of 2 words
  EXPECT_TRUE(BrickLayout::rows_for(w));
  EXPECT_EQ(BrickLayout::padded_voxels(w), 32u * 9u * 16u);
  KeyBox big = w;
  big.hi[0] = 5 + 1000, big.hi[1] = 1000 + 1000;  // 1001 x 1001 x 16 voxels: bricks
  EXPECT_FALSE(BrickLayout::rows_for(big));
  EXPECT_EQ(BrickLayout::padded_voxels(big), 126u * 126u * 4u * 256u);
  for (bool rows : {false, true}) {
    const BrickLayout layout(w, rows);
    EXPECT_EQ(layout.rows(), rows);
    const uint64_t padded = layout.voxels();
    EXPECT_EQ(padded, rows ? 32u * 9u * 16u : 3u * 2u * 4u * 256u);
    std::set<uint32_t> seen;
    for (int z = w.lo[2]; z <= w.hi[2]; ++z)
      for (int y = w.lo[1]; y <= w.hi[1]; ++y)
        for (int x = w.lo[0]; x <= w.hi[0]; ++x) {
          const octomap::OcTreeKey k(x, y, z);
          ASSERT_TRUE(layout.contains(k));
          const uint32_t i = layout.index(k);
          ASSERT_LT(i, padded);
          ASSERT_TRUE(seen.insert(i).second) << "two keys share index " << i;
          ASSERT_TRUE(layout.key_of(i / 16, i % 16) == k) << x << " " << y << " " << z << " rows " << rows;
        }
    EXPECT_FALSE(layout.contains(octomap::OcTreeKey(4, 1000, 65535)));
    EXPECT_FALSE(layout.contains(octomap::OcTreeKey(5, 1009, 65535)));
  }
}

std::set<std::tuple<int, int, int, int>> as_set(const VoxelList& l) {
  std::set<std::tuple<int, int, int, int>> s;
  for (const auto& v : l) s.insert({v.x, v.y, v.z, v.state});
  return s;
}

// One scan from `origin`: rays along the axes and axis planes both ways, diagonals, and
// random directions, of lengths from sub-voxel to `reach` metres; ends on voxel borders too.
std::vector<octomap::point3d> scan_points(const octomap::point3d& origin, float reach, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), len(0.01f, 1.0f);
  std::vector<octomap::point3d> pts;
  for (int i = 0; i < 6000; ++i) {
    octomap::point3d d(u(rng), u(rng), u(rng));
    switch (i % 6) {
      case 0: d = octomap::point3d(0, 0, 0), d(i / 6 % 3) = (i / 18) % 2 ? 1.0f : -1.0f; break;  // along an axis
      case 1: d(i / 6 % 3) = 0.0f; break;                                                        // in an axis plane
      case 2:
        d = octomap::point3d(u(rng) < 0 ? -1.0f : 1.0f, u(rng) < 0 ? -1.0f : 1.0f, u(rng) < 0 ? -1.0f : 1.0f);
        break;
      default: break;
    }
    if (d.norm() == 0.0f) continue;
    octomap::point3d e = origin + d.normalized() * (reach * len(rng));
    if (i % 7 == 0)
      e = octomap::point3d(std::round(e.x() * 10) / 10, std::round(e.y() * 10) / 10, e.z());  // on borders
    pts.push_back(e);
  }
  return pts;
}

void expect_grid_equals_cpu(const octomap::point3d& origin, float reach, uint64_t grid_bytes, unsigned threads,
                            bool expect_split, bool simd, bool helpers_yield = false,
                            uint64_t compact_alone_up_to_words = CpuGridOptions{}.compact_alone_up_to_words) {
  const double res = 0.1;
  auto reference = make_cpu_backend(res);
  auto grid = make_cpu_grid_backend({res, grid_bytes, threads, simd, helpers_yield, compact_alone_up_to_words});
  for (uint32_t seed = 1; seed <= 3; ++seed) {
    PrepareReport rep;
    const RayBatch b = prepare_scan(origin, scan_points(origin, reach, seed), seed == 2 ? reach * 0.5 : -1.0, res, rep);
    ASSERT_TRUE(rep.origin_ok);
    ASSERT_GT(b.ends.size(), 1000u);
    VoxelList a, g;
    ShootStats sa, sg;
    reference->shoot(b, Traversal::kOctomap, a, sa);
    grid->shoot(b, Traversal::kOctomap, g, sg);
    EXPECT_EQ(sg.windows > 1, expect_split)
        << "windows " << sg.windows << " seed " << seed << " origin " << origin << " box " << b.keys.voxel_count();
    ASSERT_EQ(as_set(g), as_set(a)) << "seed " << seed << " threads " << threads << " simd " << simd;
    ASSERT_EQ(g.size(), a.size()) << "a key listed twice";
  }
}

// simd = true takes the AVX2 walk where this CPU has it (window_walk_avx2.h), false the scalar one.
TEST(CpuGridBackend, BrickedWalkEqualsCpuBackendInOneWindow) {
  for (bool simd : {false, true}) {
    for (unsigned threads : {1u, 2u}) {
      expect_grid_equals_cpu({0.05f, 0.05f, 0.05f}, 12.0f, 0, threads, false, simd);        // origin at a voxel centre
      expect_grid_equals_cpu({0.8f, -1.6f, 0.4f}, 9.0f, 0, threads, false, simd);           // origin on brick borders
      expect_grid_equals_cpu({3276.0f, -3276.0f, 3270.0f}, 6.0f, 0, threads, false, simd);  // at the key range's edge
    }
  }
}

TEST(CpuGridBackend, BrickedWalkEqualsCpuBackendAcrossWindows) {
  for (bool simd : {false, true}) {
    for (unsigned threads : {1u, 2u}) {
      // 128 KiB: 512 K voxels, so a ray space of ~240^3 voxels is cut into many windows, most of
      // them without the origin (walked with a bounds test per voxel), one with it.
      expect_grid_equals_cpu({0.05f, 0.05f, 0.05f}, 12.0f, 128u << 10, threads, true, simd);
      expect_grid_equals_cpu({3276.0f, -3276.0f, 3270.0f}, 6.0f, 16u << 10, threads, true, simd);
    }
  }
}

// Rays are taken in chunks from a shared counter: 3 threads on 2 cores, helpers at the lowest
// priority (as bench and build run the walk beside the octree stage), in one and in many windows.
TEST(CpuGridBackend, YieldingHelperThreadsGiveTheSameVoxels) {
  for (bool simd : {false, true}) {
    expect_grid_equals_cpu({0.8f, -1.6f, 0.4f}, 9.0f, 0, 3, false, simd, true);
    expect_grid_equals_cpu({0.05f, 0.05f, 0.05f}, 12.0f, 128u << 10, 3, true, simd, true);
  }
}

// Compaction on every walk thread (windows that touched many words), each thread's touched
// words into its own list, joined after: the same voxels, each once.
TEST(CpuGridBackend, CompactionOnAllThreadsGivesTheSameVoxels) {
  for (unsigned threads : {2u, 3u}) {
    expect_grid_equals_cpu({0.8f, -1.6f, 0.4f}, 9.0f, 0, threads, false, true, false, 0);
    expect_grid_equals_cpu({0.05f, 0.05f, 0.05f}, 12.0f, 128u << 10, threads, true, true, true, 0);
  }
}

// Bundles of nearly equal rays: the four AVX2 lanes walk the same voxels at once, so one voxel
// found unset by several lanes waits several times in the walk's list of marks to make (and a
// word must still be listed once); each bundle long enough to fill that list many times.
TEST(CpuGridBackend, BundlesOfRaysThroughTheSameVoxelsEqualCpuBackend) {
  const double res = 0.1;
  const octomap::point3d origin(0.05f, -0.35f, 0.8f);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), jitter(-0.004f, 0.004f), len(2.0f, 15.0f);
  std::vector<octomap::point3d> pts;
  for (int bundle = 0; bundle < 300; ++bundle) {
    octomap::point3d d(u(rng), u(rng), u(rng));
    if (bundle % 5 == 0) d(bundle / 5 % 3) = 0.0f;  // in an axis plane
    if (d.norm() == 0.0f) continue;
    const octomap::point3d e = origin + d.normalized() * len(rng);
    for (int i = 0; i < 1 + bundle % 9; ++i) pts.push_back(e + octomap::point3d(jitter(rng), jitter(rng), jitter(rng)));
  }
  auto reference = make_cpu_backend(res);
  for (bool simd : {false, true}) {
    for (unsigned threads : {1u, 2u}) {
      auto grid = make_cpu_grid_backend({res, 0, threads, simd});
      for (int scan = 0; scan < 2; ++scan) {  // the second scan finds the grid cleared by the first
        PrepareReport rep;
        const RayBatch b = prepare_scan(origin, pts, scan == 1 ? 6.0 : -1.0, res, rep);
        VoxelList a, g;
        ShootStats sa, sg;
        reference->shoot(b, Traversal::kOctomap, a, sa);
        grid->shoot(b, Traversal::kOctomap, g, sg);
        ASSERT_EQ(as_set(g), as_set(a)) << "scan " << scan << " threads " << threads << " simd " << simd;
        ASSERT_EQ(g.size(), a.size()) << "a key listed twice";
        ASSERT_GT(a.size(), 10000u);
      }
    }
  }
}

// The AVX2 walk on a window of 16 x 16 x 8 voxels (2 x 2 x 2 bricks, or rows) that holds the
// origin, with most ray ends outside it: a lane stops at its end voxel by the end's grid index,
// and an end outside the window must match no voxel's (its brick arithmetic would otherwise
// name a voxel inside: x + 16 in the row of bricks above). Both layouts (in rows the index is
// kept step by step). Voxel sets equal OctoMap's walk cut to the window.
TEST(CpuGridWalk, EndsOutsideTheWindowStopNoLaneInside) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  const double res = 0.1;
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> u(-1.6f, 3.2f), uz(-0.8f, 1.6f);
  for (const octomap::point3d& origin :
       {octomap::point3d(0.001f, 1.205f, 0.15f), octomap::point3d(0.75f, 0.85f, 0.35f)}) {
    RayBatch b;
    PrepareReport rep;
    ASSERT_TRUE(prepare_origin(origin, res, b, rep));
    KeyBox w;
    for (int i = 0; i < 3; ++i) w.lo[i] = 32768, w.hi[i] = 32768 + (i < 2 ? 15 : 7);
    // From the first origin: through (0, 11, 1) to (16, 3, 1), whose brick arithmetic names (0, 11, 1).
    b.ends.push_back(RayEnd{1.65f, 0.35f, 0.15f, kRayEndOccupied});
    for (int i = 0; i < 20000; ++i)
      b.ends.push_back(RayEnd{u(rng), u(rng), uz(rng), i % 3 ? uint32_t(kRayEndOccupied) : 0u});
    for (bool rows : {false, true}) {
      const BrickLayout layout(w, rows);
      ASSERT_TRUE(layout.contains(b.origin_key));
      // Ray by ray (a union over many rays would hide one ray's early stop), then all at once.
      std::vector<uint32_t> grid(layout.voxels() / 16 + 2, 0), touched;
      int mismatches = 0;
      auto walk = [&](size_t begin, size_t end) {
        std::map<std::tuple<int, int, int>, uint32_t> expected, got;
        for (size_t r = begin; r < end; ++r) {
          const RayEnd& e = b.ends[r];
          octomap::OcTreeKey end_key;
          EXPECT_TRUE(coord_to_key_checked(octomap::point3d(e.x, e.y, e.z), res, end_key));
          walk_octomap_ray(b.origin, octomap::point3d(e.x, e.y, e.z), b.origin_key, end_key, res,
                           [&](const octomap::OcTreeKey& k) {
                             if (layout.contains(k)) expected[{k[0], k[1], k[2]}] |= kStateFree;
                           });
          if ((e.flags & kRayEndOccupied) && layout.contains(end_key))
            expected[{end_key[0], end_key[1], end_key[2]}] |= kStateOccupied;
        }
        touched.clear();
        GridMarker marker{grid.data(), touched, false};
        walk_rays_avx2(b, begin, end, layout, res, marker);
        for (uint32_t word : touched) {
          for (uint32_t slot = 0; slot < 16; ++slot)
            if (const uint32_t bits = grid[word] >> (2 * slot) & 3u) {
              const octomap::OcTreeKey k = layout.key_of(word, slot);
              got[{k[0], k[1], k[2]}] = bits;
            }
          grid[word] = 0;
        }
        if (got != expected && ++mismatches <= 3)
          ADD_FAILURE() << "origin " << origin << " rows " << rows << " rays " << begin << "-" << end << ": "
                        << got.size() << " voxels, OctoMap's walk " << expected.size();
        return expected.size();
      };
      size_t inside = 0;
      for (size_t r = 0; r < b.ends.size(); ++r) inside += walk(r, r + 1) > 1;
      EXPECT_GT(inside, 1000u);
      EXPECT_GT(walk(0, b.ends.size()), 500u);
      EXPECT_EQ(mismatches, 0);
    }
  }
}

TEST(CpuGridBackend, SaysWhetherItWalksInAvx2) {
  auto simd = make_cpu_grid_backend({0.1, 1u << 20, 1, true});
  auto scalar = make_cpu_grid_backend({0.1, 1u << 20, 1, false});
  EXPECT_EQ(simd->device_name().find("AVX2") != std::string::npos, cpu_has_avx2());
  EXPECT_EQ(scalar->device_name().find("AVX2"), std::string::npos);
}

}  // namespace
}  // namespace ort
