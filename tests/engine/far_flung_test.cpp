// Issue 13, finding 1: one valid 50-point scan with points ~3 km from the sensor wedged the
// server (a window per piece of a ~6 km box, every ray walked in each). Window planning now
// follows the rays (core/ray_tiles.h): the tiles cover every voxel OctoMap's walk visits, the
// far-flung scan's map equals OctoMap's, its cost is bounded, and what cannot be processed
// the way OctoMap does (a ray longer than OctoMap's KeyRay) or costs more than the bound is
// refused with a reason instead of shot.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/octomap_ray_walk.h"
#include "core/prepare_scan.h"
#include "core/ray_tiles.h"
#include "engine/map_engine.h"
#include "support/octomap_reference.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

// `n` points at `distance` metres from `origin` in random directions (seeded).
PosedScan far_flung_scan(const octomap::point3d& origin, double distance, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  PosedScan s;
  s.pose = octomap::pose6d(origin.x(), origin.y(), origin.z(), 0, 0, 0);
  for (int i = 0; i < n; ++i) {
    double d[3] = {g(rng), g(rng), g(rng)};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    s.points.push_back(float(d[0] / len * distance), float(d[1] / len * distance), float(d[2] / len * distance));
  }
  return s;
}

TEST(RayTiles, TilesCoverEveryVoxelTheWalkVisits) {
  const double res = 0.1;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-2500.f, 2500.f);
  std::vector<octomap::point3d> points;
  for (int i = 0; i < 40; ++i) points.emplace_back(u(rng), u(rng), u(rng) * 0.2f);
  points.emplace_back(1.05f, 2.0f, 0.5f);  // short rays too
  points.emplace_back(3.0f, 2.0f, 0.5f);
  PrepareReport report;
  const RayBatch batch = prepare_scan(octomap::point3d(1.0f, 2.0f, 0.5f), points, -1.0, res, report);
  ASSERT_EQ(batch.ends.size(), points.size());
  const int side = 256;
  const TilePlan plan = plan_ray_tiles(batch, side);
  EXPECT_EQ(plan.walk_keys, tiled_walk_keys(batch, side));
  for (uint32_t r = 0; r < batch.ends.size(); ++r) {
    const RayEnd& e = batch.ends[r];
    const octomap::point3d end(e.x, e.y, e.z);
    octomap::OcTreeKey end_key;
    ASSERT_TRUE(coord_to_key_checked(end, res, end_key));
    size_t missing = 0, visited = 0;
    auto check = [&](const octomap::OcTreeKey& k) {
      ++visited;
      bool found = false;
      for (const RayTile& t : plan.tiles) {
        if (k[0] < t.box.lo[0] || k[0] > t.box.hi[0] || k[1] < t.box.lo[1] || k[1] > t.box.hi[1] ||
            k[2] < t.box.lo[2] || k[2] > t.box.hi[2])
          continue;
        found = std::binary_search(t.rays.begin(), t.rays.end(), r);
        break;  // tiles are disjoint
      }
      missing += !found;
    };
    walk_octomap_ray(batch.origin, end, batch.origin_key, end_key, res, check);
    check(end_key);
    EXPECT_EQ(missing, 0u) << "ray " << r << ": " << missing << " of " << visited << " voxels in no tile of the ray";
  }
}

// ray_walk_keys (the per-scan work estimate) against its formula with std::floor, on ends at
// voxel borders +-1 ulp, at and past the key range's edges, negative coordinates, -0.0.
TEST(RayTiles, WalkKeysCountEqualsItsFormulaOnBordersAndRangeEdges) {
  for (double res : {0.1, 0.05, 0.25}) {
    RayBatch batch;
    batch.resolution = res;
    batch.origin = octomap::point3d(0.05f, -0.05f, 1.0f);
    PrepareReport rep;
    ASSERT_TRUE(prepare_origin(batch.origin, res, batch, rep));
    std::vector<float> coords = {0.0f, -0.0f, 1e9f, -1e9f};
    for (double v : {0.1, -0.1, 0.3, -0.3, 12.5, -12.5, 3276.7, -3276.8, 3276.8, 3300.0, -3300.0, 1638.35, -1638.4}) {
      const float f = float(v);
      coords.insert(coords.end(), {f, std::nextafter(f, 1e10f), std::nextafter(f, -1e10f)});
    }
    for (float x : coords)
      for (float y : {x, -x, 0.25f})
        for (float z : {-x, 0.0f}) {
          const RayEnd e{x, y, z, kRayEndOccupied};
          uint64_t expected = 1;
          const double c[3] = {e.x, e.y, e.z};
          for (int i = 0; i < 3; ++i) {
            const int key = int(std::clamp(std::floor(c[i] / res + 32768.0), 0.0, 65535.0));
            expected += uint64_t(std::abs(key - int(batch.origin_key[i])));
          }
          ASSERT_EQ(ray_walk_keys(batch, e), expected) << x << " " << y << " " << z << " res " << res;
        }
  }
}

// batch_walk_keys (four rays at a time in AVX2 lanes where the CPU has it) against
// ray_walk_keys ray by ray: the same sum and longest walk on ends at voxel borders +-1 ulp,
// past the key range's edges, inf, NaN, -0.0, for every count 0-9 (the lanes' remainders)
// and the whole set, with the rays in two orders (the longest walk in any lane).
TEST(RayTiles, BatchWalkKeysEqualRayByRay) {
  for (double res : {0.1, 0.05, 0.25}) {
    RayBatch batch;
    batch.resolution = res;
    batch.origin = octomap::point3d(0.05f, -0.05f, 1.0f);
    PrepareReport rep;
    ASSERT_TRUE(prepare_origin(batch.origin, res, batch, rep));
    std::vector<float> coords = {0.0f, -0.0f, 1e9f, -1e9f, INFINITY, -INFINITY, NAN};
    for (double v : {0.1, -0.1, 0.3, -0.3, 12.5, -12.5, 3276.7, -3276.8, 3276.8, 3300.0, -3300.0, 1638.35, -1638.4}) {
      const float f = float(v);
      coords.insert(coords.end(), {f, std::nextafter(f, 1e10f), std::nextafter(f, -1e10f)});
    }
    std::vector<RayEnd> all;
    for (float x : coords)
      for (float y : {x, -x, 0.25f})
        for (float z : {-x, 0.0f}) all.push_back(RayEnd{x, y, z, kRayEndOccupied});
    for (int order = 0; order < 2; ++order) {
      if (order) std::reverse(all.begin(), all.end());
      for (size_t n : {size_t(0), size_t(1), size_t(2), size_t(3), size_t(4), size_t(5), size_t(6), size_t(7),
                       size_t(8), size_t(9), all.size()}) {
        batch.ends.assign(all.begin(), all.begin() + n);
        uint64_t sum = 0, longest = 0;
        for (const RayEnd& e : batch.ends)
          sum += ray_walk_keys(batch, e), longest = std::max(longest, ray_walk_keys(batch, e));
        for (bool simd : {true, false}) {
          const WalkKeyTotals t = batch_walk_keys(batch, simd);
          EXPECT_EQ(t.sum, sum) << "res " << res << " n " << n << " simd " << simd;
          EXPECT_EQ(t.longest, longest) << "res " << res << " n " << n << " simd " << simd;
        }
      }
    }
  }
}

TEST(FarFlung, FiftyPointsThreeKilometresAwayGiveOctoMapsMapAtBoundedCost) {
  for (BackendKind kind : {BackendKind::kCpuGrid, BackendKind::kCpu}) {
    EngineOptions o;
    o.resolution = 0.1;
    o.backend.kind = kind;
    o.backend.grid_budget_bytes = 256ull << 20;  // 1G voxels: the old plan needed ~200,000 windows
    o.backend.threads = 2;
    MapEngine engine(o);
    ScanSet set;
    set.scans.push_back(far_flung_scan(octomap::point3d(1.0f, 2.0f, 0.5f), 3000.0, 50, 5));
    set.scans.push_back(far_flung_scan(octomap::point3d(-40.0f, 7.0f, 1.5f), 1500.0, 10, 6));
    auto tree = engine.make_tree();
    for (const PosedScan& s : set.scans) {
      const auto world = world_points(s);
      ShotScan shot;
      engine.insert(sensor_origin(s), std::span<const octomap::point3d>(&world[0], world.size()), *tree, shot);
      ASSERT_EQ(shot.refusal, ShotRefusal::kNone) << shot.refusal_detail;
      std::printf("  %s: %zu points, %llu tiles, %llu windows, %llu walk keys, %zu voxels\n", to_string(kind),
                  s.points.size(), (unsigned long long)shot.tiles, (unsigned long long)shot.shoot.windows,
                  (unsigned long long)shot.walk_keys, shot.voxels.size());
      if (kind == BackendKind::kCpuGrid) {
        EXPECT_GT(shot.tiles, 0u);
        EXPECT_LT(shot.shoot.windows, 20'000u);
      }
      // 50 rays of ~52,000 keys each, crossing ~100 tiles each: ~3e8, far below the bound.
      EXPECT_LT(shot.walk_keys, 1'000'000'000u);
    }
    const auto ref = octomap_reference(set, 0.1, -1.0);
    const TreeDiff d = compare_leaves(*tree, *ref);
    EXPECT_TRUE(d.maps_equal()) << to_string(kind) << ": " << d.differing_voxels << " voxels, " << d.differing_logodds
                                << " log-odds differ: " << d.first_difference;
  }
}

// The daemon hands sensor-frame scans to the vulkan back end, which prepares them on the
// device (shoot_posed). A far-flung scan must not be planned there from its bounding box: the
// device declines it and the engine tiles it on the CPU path; the map still equals OctoMap's
// and no ray walk hits the shaders' step guard. Near scans stay on the device.
TEST(FarFlung, SensorFrameScansOnTheVulkanBackEndAreTiledNotWedged) {
  EngineOptions o;
  o.resolution = 0.1;
  o.backend.kind = BackendKind::kVulkan;
  o.backend.grid_budget_bytes = 256ull << 20;
  std::unique_ptr<MapEngine> engine;
  try {
    engine = std::make_unique<MapEngine>(o);
  } catch (const Unsupported& e) {
    GTEST_SKIP() << "no Vulkan device: " << e.what();
  }
  ASSERT_TRUE(engine->backend().prepares_on_device());
  ScanSet set;
  // 400 m at 0.1 m: a key box of ~8000^3 voxels, far above one window plan (2^30).
  set.scans.push_back(far_flung_scan(octomap::point3d(1.0f, 2.0f, 0.5f), 400.0, 50, 5));
  set.scans.push_back(far_flung_scan(octomap::point3d(-40.0f, 7.0f, 1.5f), 8.0, 200, 7));  // near: on the device
  auto tree = engine->make_tree();
  for (size_t i = 0; i < set.scans.size(); ++i) {
    const PosedScan& s = set.scans[i];
    ShotScan shot;
    engine->insert_posed(s.pose, sensor_origin(s), std::span<const octomap::point3d>(&s.points[0], s.points.size()),
                         *tree, shot);
    ASSERT_EQ(shot.refusal, ShotRefusal::kNone) << shot.refusal_detail;
    EXPECT_EQ(shot.shoot.walk_overruns, 0u) << "scan " << i;
    EXPECT_EQ(shot.prepare.device_declined, i == 0) << "scan " << i;
    if (i == 0) {
      EXPECT_GT(shot.tiles, 0u);
      EXPECT_LT(shot.shoot.windows, 20'000u);
    }
  }
  const auto ref = octomap_reference(set, 0.1, -1.0);
  const TreeDiff d = compare_leaves(*tree, *ref);
  EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels, " << d.differing_logodds
                              << " log-odds differ: " << d.first_difference;
}

TEST(FarFlung, WhatOctoMapCannotWalkOrTheBoundForbidsIsRefused) {
  EngineOptions o;
  o.resolution = 0.1;
  o.backend.kind = BackendKind::kCpuGrid;
  o.backend.grid_budget_bytes = 16ull << 20;
  MapEngine engine(o);
  // Corner to corner of the key range: 3 x ~64,000 keys, beyond OctoMap's 100,000-key KeyRay
  // (OctoMap itself would write past its buffer).
  const octomap::point3d origin(-3200.0f, -3200.0f, -3200.0f);
  const std::vector<octomap::point3d> far = {octomap::point3d(3200.0f, 3200.0f, 3200.0f)};
  ShotScan shot;
  engine.shoot(origin, far, -1.0, shot);
  EXPECT_EQ(shot.refusal, ShotRefusal::kRayTooLong);
  EXPECT_NE(shot.refusal_detail.find("OctoMap"), std::string::npos) << shot.refusal_detail;
  EXPECT_TRUE(shot.voxels.empty());

  o.max_scan_walk_keys = 1000;
  MapEngine bounded(o);
  const std::vector<octomap::point3d> near = {octomap::point3d(500.0f, 0.0f, 0.0f)};
  bounded.shoot(octomap::point3d(0, 0, 0), near, -1.0, shot);
  EXPECT_EQ(shot.refusal, ShotRefusal::kTooMuchWork);
  EXPECT_TRUE(shot.voxels.empty());
}

}  // namespace
}  // namespace ort::test
