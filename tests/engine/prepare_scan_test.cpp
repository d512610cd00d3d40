// Bad input at the engine's door: NaN/inf points are skipped and counted, points outside the
// key range are counted, an empty scan is fine, a bad origin rejects the scan.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "core/prepare_scan.h"
#include "engine/map_engine.h"

namespace ort {
namespace {

TEST(PrepareScan, SkipsAndCountsNonFiniteAndOutOfRangePoints) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<octomap::point3d> pts = {{1, 2, 3}, {nan, 0, 0}, {0, inf, 0}, {0, 0, -inf}, {1e6f, 0, 0}, {2, 2, 2}};
  PrepareReport r;
  const RayBatch b = prepare_scan({0, 0, 0}, pts, -1.0, 0.1, r);
  EXPECT_EQ(r.points_in, 6u);
  EXPECT_EQ(r.nonfinite, 3u);
  EXPECT_EQ(r.out_of_range, 1u);  // 1e6 m is beyond 32768 * 0.1 m
  EXPECT_EQ(r.rays, 2u);
  ASSERT_EQ(b.ends.size(), 2u);
  EXPECT_EQ(b.ends[0].flags, kRayEndOccupied);
}

TEST(PrepareScan, CutsAtMaxRangeAsOctomapDoes) {
  std::vector<octomap::point3d> pts = {{20, 0, 0}, {3, 4, 0}};
  PrepareReport r;
  const RayBatch b = prepare_scan({0, 0, 0}, pts, 5.0, 0.1, r);
  ASSERT_EQ(b.ends.size(), 2u);
  EXPECT_EQ(r.cut_at_max_range, 1u);
  EXPECT_EQ(b.ends[0].flags, 0u);  // cut: free space only
  EXPECT_FLOAT_EQ(b.ends[0].x, 5.0f);
  EXPECT_EQ(b.ends[1].flags, kRayEndOccupied);  // exactly at max range: kept (<=)
}

TEST(PrepareScan, BadOriginRejectsTheScan) {
  std::vector<octomap::point3d> pts = {{1, 1, 1}};
  PrepareReport r;
  prepare_scan({std::numeric_limits<float>::quiet_NaN(), 0, 0}, pts, -1.0, 0.1, r);
  EXPECT_FALSE(r.origin_ok);
  EXPECT_FALSE(r.error.empty());
  PrepareReport r2;
  prepare_scan({5000.0f, 0, 0}, pts, -1.0, 0.1, r2);
  EXPECT_FALSE(r2.origin_ok);
}

TEST(MapEngine, EmptyScanIsFine) {
  EngineOptions o;
  o.backend.kind = BackendKind::kCpu;
  MapEngine engine(o);
  auto tree = engine.make_tree();
  ShotScan shot;
  engine.insert({0, 0, 0}, {}, *tree, shot);
  EXPECT_TRUE(shot.prepare.origin_ok);
  EXPECT_EQ(shot.voxels.size(), 0u);
  EXPECT_EQ(tree->size(), 0u);
}

TEST(CoordToKey, MatchesOctomap) {
  octomap::OcTree tree(0.1);
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-3300.0f, 3300.0f);
  for (int i = 0; i < 100000; ++i) {
    const octomap::point3d p(u(rng), u(rng) * 0.001f, -u(rng));
    octomap::OcTreeKey a, b;
    const bool ok_a = tree.coordToKeyChecked(p, a);
    const bool ok_b = coord_to_key_checked(p, 0.1, b);
    ASSERT_EQ(ok_a, ok_b) << p;
    if (ok_a) {
      ASSERT_TRUE(a == b) << p;
    }
  }
}

// The inline floor (truncation, one down when above): voxel borders on both sides of zero,
// -0.0, the key range's edges, non-finite values, several resolutions.
TEST(CoordToKey, MatchesOctomapOnBordersAndRangeEdges) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (double res : {0.1, 0.05, 0.2, 0.3, 1.0}) {
    octomap::OcTree tree(res);
    const float edge = float(32768 * res);
    std::vector<float> values = {0.0f,
                                 -0.0f,
                                 inf,
                                 -inf,
                                 nan,
                                 edge,
                                 -edge,
                                 std::nextafter(edge, 0.0f),
                                 std::nextafter(-edge, 0.0f),
                                 std::nextafter(-edge, -2 * edge),
                                 1e-30f,
                                 -1e-30f};
    for (int k = -300; k <= 300; ++k) {
      const float border = float(k * res);
      for (float v : {border, std::nextafter(border, inf), std::nextafter(border, -inf)}) values.push_back(v);
    }
    for (float v : values) {
      const octomap::point3d p(v, -v, 0.5f * v);
      octomap::OcTreeKey a, b;
      const bool ok_a = tree.coordToKeyChecked(p, a);
      const bool ok_b = coord_to_key_checked(p, res, b);
      ASSERT_EQ(ok_a, ok_b) << p << " res " << res;
      if (ok_a) {
        ASSERT_TRUE(a == b) << p << " res " << res;
      }
    }
  }
}

TEST(PrepareScan, ThreadsGiveTheSameBatchRayForRay) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> u(-40.0f, 40.0f);
  std::vector<octomap::point3d> pts;
  for (int i = 0; i < 200000; ++i) {
    octomap::point3d p(u(rng), u(rng), u(rng));
    if (i % 997 == 0) p.x() = std::numeric_limits<float>::quiet_NaN();
    if (i % 1499 == 0) p.y() = 1e7f;  // outside the key range
    pts.push_back(p);
  }
  for (double max_range : {-1.0, 25.0}) {
    PrepareReport r1, r7;
    const RayBatch b1 = prepare_scan({1, 2, 3}, pts, max_range, 0.1, r1, 1);
    const RayBatch b7 = prepare_scan({1, 2, 3}, pts, max_range, 0.1, r7, 7);
    EXPECT_EQ(r1.rays, r7.rays);
    EXPECT_EQ(r1.nonfinite, r7.nonfinite);
    EXPECT_EQ(r1.out_of_range, r7.out_of_range);
    EXPECT_EQ(r1.cut_at_max_range, r7.cut_at_max_range);
    EXPECT_GT(r1.nonfinite, 0u);
    if (max_range < 0) {  // with a max range they are cut, not dropped
      EXPECT_GT(r1.out_of_range, 0u);
    }
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(b1.keys.lo[i], b7.keys.lo[i]);
      EXPECT_EQ(b1.keys.hi[i], b7.keys.hi[i]);
    }
    ASSERT_EQ(b1.ends.size(), b7.ends.size());
    for (size_t i = 0; i < b1.ends.size(); ++i) {
      ASSERT_EQ(b1.ends[i].x, b7.ends[i].x);
      ASSERT_EQ(b1.ends[i].y, b7.ends[i].y);
      ASSERT_EQ(b1.ends[i].z, b7.ends[i].z);
      ASSERT_EQ(b1.ends[i].flags, b7.ends[i].flags);
    }
  }
}

// The AVX2 preparation (four points at a time) against the point-by-point loop: the same
// rays in the same order, the same key box and counts, on points at voxel borders +-1 ulp,
// at and past the key range's edges, -0.0, NaN and inf in any lane, and counts not a multiple
// of four; with and without a max range (which takes the point-by-point loop).
TEST(PrepareScan, FourPointsAtATimeGiveThePointByPointBatch) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-60.0f, 60.0f);
  std::uniform_int_distribution<int> pick(0, 15);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const float special[] = {0.0f,     -0.0f,   0.1f,     -0.1f, 0.3f, -0.3f, 3276.7f,
                           -3276.8f, 3276.8f, -3276.9f, 1e7f,  nan,  inf,   -inf};
  for (double res : {0.1, 0.05}) {
    for (size_t count : {0u, 1u, 3u, 4u, 7u, 50001u}) {
      std::vector<octomap::point3d> pts;
      for (size_t i = 0; i < count; ++i) {
        octomap::point3d p(u(rng), u(rng), u(rng));
        for (int a = 0; a < 3; ++a) {
          const int k = pick(rng);
          if (k < 14 && i % 5 == 0)
            p(a) = special[k];
          else if (k == 14)
            p(a) = std::nextafter(std::round(p(a) * 10) / 10, 1e9f);
          else if (k == 15)
            p(a) = std::nextafter(std::round(p(a) * 10) / 10, -1e9f);
        }
        pts.push_back(p);
      }
      for (double max_range : {-1.0, 30.0}) {
        PrepareReport rs, rv;
        const RayBatch s = prepare_scan({0.05f, -2.0f, 1.0f}, pts, max_range, res, rs, 1, false);
        const RayBatch v = prepare_scan({0.05f, -2.0f, 1.0f}, pts, max_range, res, rv, 1, true);
        EXPECT_EQ(rs.rays, rv.rays);
        EXPECT_EQ(rs.nonfinite, rv.nonfinite);
        EXPECT_EQ(rs.out_of_range, rv.out_of_range);
        EXPECT_EQ(rs.cut_at_max_range, rv.cut_at_max_range);
        if (count > 1000) {
          EXPECT_GT(rs.nonfinite, 0u);
        }
        for (int i = 0; i < 3; ++i) {
          EXPECT_EQ(s.keys.lo[i], v.keys.lo[i]) << "count " << count;
          EXPECT_EQ(s.keys.hi[i], v.keys.hi[i]) << "count " << count;
        }
        ASSERT_EQ(s.ends.size(), v.ends.size());
        ASSERT_EQ(0, std::memcmp(s.ends.data(), v.ends.data(), s.ends.size() * sizeof(RayEnd))) << "count " << count;
      }
    }
  }
}

}  // namespace
}  // namespace ort
