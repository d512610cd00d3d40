// Issue 21, the crash: a ray whose end lies in another voxel than the origin, at a float
// distance of 0 from it (a max range of 1e-30, or a point at -1e-30 beside an origin at 0 on
// a voxel border), made OctoMap's computeRayKeys (the cpu back end) write past its KeyRay and
// the cpu-grid walk read outside its window. Such rays are now skipped and counted at
// preparation, on every back end (the GPU ones where a device exists, else skipped), and the
// map is OctoMap's insertPointCloud of the other points.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/prepare_scan.h"
#include "engine/map_engine.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

// The rt back end walks the exact traversal only (its map is compared with the cpu back
// end's exact walk); the others OctoMap's (compared with OctoMap itself).
Traversal traversal_of(BackendKind kind) { return kind == BackendKind::kRt ? Traversal::kExact : Traversal::kOctomap; }

std::unique_ptr<MapEngine> make_engine(BackendKind kind) {
  EngineOptions o;
  o.resolution = 0.1;
  o.backend.kind = kind;
  o.traversal = traversal_of(kind);
  o.backend.grid_budget_bytes = 64ull << 20;
  o.octree.threads = 1;
  return std::make_unique<MapEngine>(o);
}

// Ordinary points around an origin at 0 (a map-frame origin on a voxel border on all three
// axes), with `bad` points within 1e-19 m of it on the other side of a border mixed in, in
// groups of four as the AVX2 preparation takes them.
std::vector<octomap::point3d> points_with_degenerate_rays(std::vector<octomap::point3d>& good) {
  std::vector<octomap::point3d> all;
  const std::vector<octomap::point3d> bad = {
      {-1e-30f, 0, 0}, {0, -1e-25f, 1e-30f}, {1e-30f, 1e-30f, -1e-38f}, {-1e-23f, -1e-23f, -1e-23f}, {-1.4e-45f, 0, 0}};
  for (int i = 0; i < 40; ++i) {
    const float a = 0.37f * float(i);
    good.push_back({2.0f * std::cos(a), 2.0f * std::sin(a), 0.1f * float(i % 7) - 0.3f});
  }
  size_t b = 0;
  for (size_t i = 0; i < good.size(); ++i) {
    all.push_back(good[i]);
    if (i % 7 == 2 && b < bad.size()) all.push_back(bad[b++]);
  }
  while (b < bad.size()) all.push_back(bad[b++]);
  return all;
}

class DegenerateRays : public ::testing::TestWithParam<BackendKind> {
 protected:
  void SetUp() override {
    try {
      engine_ = make_engine(GetParam());
    } catch (const Unsupported& e) {
      GTEST_SKIP() << "no device for " << to_string(GetParam()) << ": " << e.what();
    } catch (const std::runtime_error& e) {
      GTEST_SKIP() << "no device for " << to_string(GetParam()) << ": " << e.what();
    }
  }
  std::unique_ptr<MapEngine> engine_;
};

TEST_P(DegenerateRays, PointsAtAFloatDistanceOfZeroAcrossABorderAreSkippedAndCounted) {
  std::vector<octomap::point3d> good;
  const std::vector<octomap::point3d> all = points_with_degenerate_rays(good);
  const octomap::point3d origin(0, 0, 0);
  for (bool posed : {false, true}) {
    auto tree = engine_->make_tree();
    ShotScan shot;
    if (posed) {  // the sensor-frame path: prepared on the device where the back end can
      engine_->insert_posed(octomap::pose6d(0, 0, 0, 0, 0, 0), origin, all, *tree, shot);
    } else {
      engine_->insert(origin, all, *tree, shot);
    }
    ASSERT_TRUE(shot.prepare.origin_ok);
    EXPECT_EQ(shot.prepare.degenerate, 5u) << (posed ? "posed" : "map frame");
    EXPECT_EQ(shot.prepare.rays, good.size());
    EXPECT_EQ(shot.shoot.walk_overruns, 0u);
    octomap::OcTree ref(0.1);
    if (traversal_of(GetParam()) == Traversal::kOctomap) {
      octomap::Pointcloud cloud;
      for (const auto& p : good) cloud.push_back(p);
      ref.insertPointCloud(cloud, origin, -1.0, false, false);
    } else {
      const auto cpu = make_engine(BackendKind::kCpu);
      EngineOptions o = cpu->options();
      o.traversal = Traversal::kExact;
      MapEngine exact(o);
      ShotScan s;
      exact.insert(origin, good, ref, s);
    }
    const TreeDiff d = compare_leaves(*tree, ref);
    EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels differ: " << d.first_difference;
  }
}

TEST_P(DegenerateRays, AMaxRangeFarBelowTheResolutionWalksNothing) {
  // Every ray is cut to within 1e-30 m of the origin at 0: those that cross a border there
  // are degenerate, the others stay in the origin's voxel (free space only, no walk).
  std::vector<octomap::point3d> good;
  const std::vector<octomap::point3d> all = points_with_degenerate_rays(good);
  for (bool posed : {false, true}) {
    auto tree = engine_->make_tree();
    ShotScan shot;
    const octomap::point3d origin(0, 0, 0);
    if (posed) {
      engine_->shoot_posed(octomap::pose6d(0, 0, 0, 0, 0, 0), origin, all, 1e-30, shot);
    } else {
      engine_->shoot(origin, all, 1e-30, shot);
    }
    engine_->apply(shot, *tree);
    ASSERT_TRUE(shot.prepare.origin_ok);
    EXPECT_GT(shot.prepare.degenerate, 0u);
    EXPECT_EQ(shot.prepare.degenerate + shot.prepare.rays, all.size());
    EXPECT_EQ(shot.shoot.walk_overruns, 0u);
    EXPECT_EQ(tree->size(), 0u) << "a cut ray inside the origin's voxel changes nothing";
  }
}

INSTANTIATE_TEST_SUITE_P(EveryBackEnd, DegenerateRays,
                         ::testing::Values(BackendKind::kCpu, BackendKind::kCpuGrid, BackendKind::kVulkan,
                                           BackendKind::kRt),
                         [](const auto& info) {
                           std::string n = to_string(info.param);
                           for (char& c : n)
                             if (c == '-') c = '_';
                           return n;
                         });

TEST(DegenerateRays, FourPointsAtATimeSendNearOriginGroupsToThePointByPointRules) {
  std::vector<octomap::point3d> good;
  const std::vector<octomap::point3d> all = points_with_degenerate_rays(good);
  PrepareReport simd, scalar;
  const RayBatch a = prepare_scan({0, 0, 0}, all, -1.0, 0.1, simd, 1, true);
  const RayBatch b = prepare_scan({0, 0, 0}, all, -1.0, 0.1, scalar, 1, false);
  EXPECT_EQ(simd.degenerate, 5u);
  EXPECT_EQ(scalar.degenerate, 5u);
  ASSERT_EQ(a.ends.size(), b.ends.size());
  for (size_t i = 0; i < a.ends.size(); ++i) EXPECT_EQ(a.ends[i].x, b.ends[i].x) << i;
}

}  // namespace
}  // namespace ort::test
