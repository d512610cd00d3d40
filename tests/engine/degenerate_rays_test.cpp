// Issue 21: rays near the sensor that OctoMap's float walk cannot take, and coordinates so
// small that a GPU flushing fp32 subnormals (NVIDIA's) would read them otherwise than the
// CPU. The scan contract (core/prepare_scan.h) reads a coordinate below kTinyCoordinate as 0
// and skips a ray whose end lies nearer than kMinRayLength to the origin across a voxel
// border; every back end (the GPU ones where a device exists, else skipped) then gives
// OctoMap's insertPointCloud of the points as the contract reads them. Before the rules such
// rays made OctoMap's computeRayKeys (the cpu back end) write past its KeyRay and the
// cpu-grid walk read outside its window; before the second version of them, the vulkan and
// rt back ends on an H200 classified them differently from OctoMap.
#include <cfenv>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#if defined(__x86_64__)
#include <xmmintrin.h>
#endif

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/prepare_scan.h"
#include "engine/map_engine.h"
#include "support/every_backend.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

std::unique_ptr<MapEngine> make_engine(BackendKind kind, Traversal traversal) {
  EngineOptions o;
  o.resolution = 0.1;
  o.backend.kind = kind;
  o.traversal = traversal;
  o.backend.grid_budget_bytes = 64ull << 20;
  o.backend.threads = 1;
  o.octree.threads = 1;
  return std::make_unique<MapEngine>(o);
}

// A scan around a sensor at 0 (on a voxel border on all three axes): ordinary points, and in
// groups of four as the AVX2 preparation takes them, points the contract reads otherwise or
// skips. `expected` is the cloud as the contract reads it, the one OctoMap is given.
struct NearOriginScan {
  std::vector<octomap::point3d> all, expected;
  uint64_t degenerate = 0, read_as_zero = 0;
};

NearOriginScan near_origin_scan() {
  NearOriginScan s;
  std::vector<octomap::point3d> good;
  for (int i = 0; i < 40; ++i) {
    const float a = 0.37f * float(i);
    good.push_back({2.0f * std::cos(a), 2.0f * std::sin(a), 0.1f * float(i % 7) - 0.3f});
  }
  // Below kTinyCoordinate (subnormals among them: a flushing GPU reads those as 0 on its own):
  // read as 0; the ray then ends in the origin's voxel, or is an ordinary ray.
  const std::vector<std::pair<octomap::point3d, octomap::point3d>> tiny = {
      {{-1e-30f, 0, 0}, {0, 0, 0}},           {{0, -1e-25f, 1e-30f}, {0, 0, 0}},
      {{1e-30f, 1e-30f, -1e-38f}, {0, 0, 0}}, {{-1e-23f, -1e-23f, -1e-23f}, {0, 0, 0}},
      {{-1.4e-45f, 0, 0}, {0, 0, 0}},         {{-1e-30f, 0.35f, 0}, {0, 0.35f, 0}},
  };
  // Across a border nearer than kMinRayLength on every axis: skipped. The squared length of
  // the first is a subnormal float (a flushing GPU would walk a length of 0).
  const std::vector<octomap::point3d> too_short = {
      {-1e-19f, 0, 0}, {3e-20f, -5e-16f, 2e-18f}, {-4e-16f, -4e-16f, 0}, {2e-20f, -3e-20f, 5e-20f}};
  // Just beyond it: ordinary (very short) walks, one with a subnormal square among its terms.
  const std::vector<octomap::point3d> short_walks = {{-2e-15f, 0, 0}, {1e-14f, -3e-15f, 1e-19f}};
  std::vector<std::pair<octomap::point3d, const octomap::point3d*>> odd;  // point, expected reading (null: skipped)
  for (const auto& [p, read] : tiny) odd.push_back({p, &read});
  for (const auto& p : too_short) odd.push_back({p, nullptr});
  for (const auto& p : short_walks) odd.push_back({p, &p});
  size_t b = 0;
  auto add_odd = [&] {
    s.all.push_back(odd[b].first);
    if (odd[b].second) s.expected.push_back(*odd[b].second);
    ++b;
  };
  for (size_t i = 0; i < good.size(); ++i) {
    s.all.push_back(good[i]);
    s.expected.push_back(good[i]);
    if (i % 3 == 1 && b < odd.size()) add_odd();
  }
  while (b < odd.size()) add_odd();
  s.degenerate = too_short.size();
  s.read_as_zero = tiny.size();
  return s;
}

// The reference map: OctoMap's insertPointCloud of the contract's reading (octomap traversal),
// or the cpu back end's exact walk of it (exact traversal).
std::unique_ptr<octomap::OcTree> reference(Traversal traversal, const octomap::point3d& origin,
                                           const std::vector<octomap::point3d>& points, double max_range) {
  auto ref = std::make_unique<octomap::OcTree>(0.1);
  if (traversal == Traversal::kOctomap) {
    octomap::Pointcloud cloud;
    for (const auto& p : points) cloud.push_back(p);
    ref->insertPointCloud(cloud, origin, max_range, false, false);
  } else {
    const auto exact = make_engine(BackendKind::kCpu, Traversal::kExact);
    ShotScan s;
    exact->shoot(origin, points, max_range, s);
    exact->apply(s, *ref);
  }
  return ref;
}

class DegenerateRays : public ::testing::TestWithParam<BackendKind> {
 protected:
  void SetUp() override {
    try {
      engine_ = make_engine(GetParam(), reference_traversal(GetParam()));
    } catch (const Unsupported& e) {
      GTEST_SKIP() << "no device for " << to_string(GetParam()) << ": " << e.what();
    } catch (const std::runtime_error& e) {
      GTEST_SKIP() << "no device for " << to_string(GetParam()) << ": " << e.what();
    }
  }
  // The scan shot from `origin` (map frame, or sensor frame with an identity pose: the
  // device-prepared path where the back end has one) and applied to a fresh map.
  std::unique_ptr<octomap::OcTree> shoot(const NearOriginScan& s, const octomap::point3d& origin, double max_range,
                                         bool posed, ShotScan& shot) {
    auto tree = engine_->make_tree();
    if (posed) {
      engine_->shoot_posed(octomap::pose6d(0, 0, 0, 0, 0, 0), origin, s.all, max_range, shot);
    } else {
      engine_->shoot(origin, s.all, max_range, shot);
    }
    engine_->apply(shot, *tree);
    return tree;
  }
  std::unique_ptr<MapEngine> engine_;
};

TEST_P(DegenerateRays, TinyCoordinatesReadAsZeroAndTooShortRaysAreSkippedAsOctomapWouldMapTheRest) {
  const NearOriginScan s = near_origin_scan();
  // The second origin is the first as the contract reads it (tiny coordinates, a subnormal).
  for (const octomap::point3d& origin : {octomap::point3d(0, 0, 0), octomap::point3d(-1e-25f, 1e-39f, 0)}) {
    for (bool posed : {false, true}) {
      SCOPED_TRACE(std::string(posed ? "sensor frame" : "map frame") + ", origin x " + std::to_string(origin.x()));
      ShotScan shot;
      const auto tree = shoot(s, origin, -1.0, posed, shot);
      ASSERT_TRUE(shot.prepare.origin_ok);
      EXPECT_EQ(shot.prepare.degenerate, s.degenerate);
      EXPECT_EQ(shot.prepare.read_as_zero, s.read_as_zero);
      EXPECT_EQ(shot.prepare.rays, s.expected.size());
      EXPECT_EQ(shot.shoot.walk_overruns, 0u);
      const auto ref = reference(reference_traversal(GetParam()), octomap::point3d(0, 0, 0), s.expected, -1.0);
      const TreeDiff d = compare_leaves(*tree, *ref);
      EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels differ: " << d.first_difference;
    }
  }
}

TEST_P(DegenerateRays, AtTheSmallestMaxRangeEveryRayIsCutAsOctomapCutsIt) {
  // Every ray longer than 1 mm is cut there: near the origin's corner, a few of them across
  // its borders; the too-short ones are within range and skipped as before.
  const NearOriginScan s = near_origin_scan();
  for (bool posed : {false, true}) {
    SCOPED_TRACE(posed ? "sensor frame" : "map frame");
    ShotScan shot;
    const auto tree = shoot(s, octomap::point3d(0, 0, 0), kMinMaxRange, posed, shot);
    ASSERT_TRUE(shot.prepare.origin_ok);
    EXPECT_EQ(shot.prepare.degenerate, s.degenerate);
    EXPECT_EQ(shot.prepare.degenerate + shot.prepare.rays, s.all.size());
    EXPECT_GT(shot.prepare.cut_at_max_range, 40u);
    EXPECT_EQ(shot.shoot.walk_overruns, 0u);
    const auto ref = reference(reference_traversal(GetParam()), octomap::point3d(0, 0, 0), s.expected, kMinMaxRange);
    EXPECT_GT(ref->size(), 0u);
    const TreeDiff d = compare_leaves(*tree, *ref);
    EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels differ: " << d.first_difference;
  }
}

TEST_P(DegenerateRays, AMaxRangeBelowTheSmallestIsRefused) {
  // Below 1 mm, whether a ray is cut would depend on squares a GPU may flush: refused (the
  // scan message and the flags refuse it before the engine).
  const NearOriginScan s = near_origin_scan();
  for (double max_range : {1e-30, 0.0, 0.5e-3, std::nan("")}) {
    ShotScan shot;
    EXPECT_THROW(engine_->shoot(octomap::point3d(0, 0, 0), s.all, max_range, shot), std::invalid_argument) << max_range;
    EXPECT_THROW(
        engine_->shoot_posed(octomap::pose6d(0, 0, 0, 0, 0, 0), octomap::point3d(0, 0, 0), s.all, max_range, shot),
        std::invalid_argument)
        << max_range;
  }
}

INSTANTIATE_TEST_SUITE_P(EveryBackEnd, DegenerateRays, kEveryBackend, backend_param_name);

TEST(DegenerateRays, FourPointsAtATimeSendNearOriginGroupsToThePointByPointRules) {
  const NearOriginScan s = near_origin_scan();
  PrepareReport simd, scalar;
  const RayBatch a = prepare_scan({0, 0, 0}, s.all, -1.0, 0.1, simd, 1, true);
  const RayBatch b = prepare_scan({0, 0, 0}, s.all, -1.0, 0.1, scalar, 1, false);
  EXPECT_EQ(simd.degenerate, s.degenerate);
  EXPECT_EQ(scalar.degenerate, s.degenerate);
  EXPECT_EQ(simd.read_as_zero, s.read_as_zero);
  EXPECT_EQ(scalar.read_as_zero, s.read_as_zero);
  ASSERT_EQ(a.ends.size(), s.expected.size());
  ASSERT_EQ(a.ends.size(), b.ends.size());
  for (size_t i = 0; i < a.ends.size(); ++i) {
    EXPECT_EQ(a.ends[i].x, s.expected[i].x()) << i;
    EXPECT_EQ(a.ends[i].y, s.expected[i].y()) << i;
    EXPECT_EQ(a.ends[i].z, s.expected[i].z()) << i;
    EXPECT_EQ(a.ends[i].x, b.ends[i].x) << i;
    EXPECT_EQ(a.ends[i].flags, b.ends[i].flags) << i;
  }
}

#if defined(__x86_64__)
// The CPU made to flush subnormals as NVIDIA's GPUs do (MXCSR flush-to-zero and
// denormals-are-zero, this thread only): the cpu back end (our preparation, OctoMap's own
// walk) still gives the map OctoMap gives without flushing. Without the contract's rules the
// subnormal coordinates and the subnormal squared length above change keys and walks here.
TEST(DegenerateRays, AFlushingProcessorGivesTheMapOfOneThatDoesNot) {
  const NearOriginScan s = near_origin_scan();
  const auto ref = reference(Traversal::kOctomap, octomap::point3d(0, 0, 0), s.expected, -1.0);
  const auto engine = make_engine(BackendKind::kCpu, Traversal::kOctomap);
  auto tree = engine->make_tree();
  ShotScan shot;
  const unsigned saved = _mm_getcsr();
  _mm_setcsr(saved | 0x8040);  // FTZ (bit 15) and DAZ (bit 6)
  engine->shoot(octomap::point3d(0, 0, 0), s.all, -1.0, shot);
  _mm_setcsr(saved);
  engine->apply(shot, *tree);
  EXPECT_EQ(shot.prepare.degenerate, s.degenerate);
  const TreeDiff d = compare_leaves(*tree, *ref);
  EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels differ: " << d.first_difference;
}
#endif

}  // namespace
}  // namespace ort::test
