// The persistent shared ray space of the `vulkan` back end: windows when a scan's ray space
// exceeds the grid, chunked compaction when a window touches more words than one pass can
// emit, no waste (exactly the touched words are read back and cleared; the grid is
// allocated once), and "occupied wins" inside one scan. Each result is compared with the
// cpu back end (OctoMap's computeRayKeys / the exact reference).
#include <cmath>
#include <cstdlib>
#include <random>

#include <gtest/gtest.h>

#include "core/prepare_scan.h"
#include "core/ray_space.h"
#include "engine/backend_factory.h"
#include "gpu/gpu_test_support.h"
#include "gpu/ray_space_sizing.h"
#include "gpu/vulkan_backend.h"
#include "scene/synthetic_scene.h"

namespace ort::test {
namespace {

RayBatch synthetic_batch(size_t scan, double resolution, double max_range, size_t every = 1) {
  static const ScanSet set = make_synthetic_rooms();
  const PosedScan& s = set.scans.at(scan);
  const octomap::Pointcloud world = world_points(s);
  std::vector<octomap::point3d> points;
  for (size_t i = 0; i < world.size(); i += every) points.push_back(world[i]);
  PrepareReport report;
  return prepare_scan(sensor_origin(s), points, max_range, resolution, report);
}

VoxelList cpu_states(const RayBatch& batch, Traversal mode) {
  BackendOptions o;
  o.kind = BackendKind::kCpu;
  o.resolution = batch.resolution;
  auto cpu = make_backend(o);
  VoxelList v;
  ShootStats stats;
  cpu->shoot(batch, mode, v, stats);
  sort_voxels(v);
  return v;
}

TEST(VulkanRaySpace, TinyGridSplitsScansIntoWindowsAndStillEqualsCpu) {
  // 8 KiB: 2048 words, 32768 voxels a window, far less than a room scan's ray space.
  auto gpu = make_vulkan(0.1, -1.0, 8 << 10);
  uint64_t grid_words = 0;
  for (size_t scan = 0; scan < 2; ++scan) {
    for (Traversal mode : {Traversal::kOctomap, Traversal::kExact}) {
      const RayBatch batch = synthetic_batch(scan, 0.1, -1.0, 4);
      VoxelList got;
      ShootStats stats;
      gpu->shoot(batch, mode, got, stats);
      sort_voxels(got);
      const VoxelList want = cpu_states(batch, mode);
      EXPECT_TRUE(same_voxels(got, want))
          << to_string(mode) << " scan " << scan << ": " << diff_voxels(got, want, batch, mode).substr(0, 2000);
      EXPECT_GE(stats.windows, 8u) << "ray space " << batch.keys.voxel_count() << " voxels";
      std::printf("%s scan %zu: %zu rays, %llu windows, %zu voxels\n", to_string(mode), scan, batch.ends.size(),
                  (unsigned long long)stats.windows, got.size());
      EXPECT_EQ(stats.words_read_back, stats.words_touched);
      EXPECT_GT(stats.words_touched, 0u);
      EXPECT_LE(stats.words_touched * 16, want.size() * 16);  // a word is listed only if it holds a voxel
      EXPECT_GE(stats.words_touched * 16, want.size());
      EXPECT_EQ(stats.grid_allocations, 1u);
      if (grid_words == 0) grid_words = stats.grid_words;
      EXPECT_EQ(stats.grid_words, grid_words);
      EXPECT_EQ(grid_words, (8u << 10) / 4);
    }
  }
}

TEST(VulkanRaySpace, AGridSizedFromTheScansGrowsToThemAndStillEqualsCpu) {
  // No max range and no budget given: the grid starts at 2048 words (32768 voxels, far less
  // than a room scan's ray space) and grows to what the scans need, each then in one window.
  BackendOptions o;
  o.kind = BackendKind::kVulkan;
  o.resolution = 0.1;
  if (const char* d = std::getenv("OCTOMAP_RT_TEST_DEVICE")) o.device = d;
  VulkanTuning tuning;
  tuning.start_grid_words = 2048;
  auto gpu = make_vulkan_backend(o, tuning);
  uint64_t allocations = 0;
  for (size_t scan : {size_t(0), size_t(1), size_t(0)}) {
    const RayBatch batch = synthetic_batch(scan, 0.1, -1.0, 4);
    VoxelList got;
    ShootStats stats;
    gpu->shoot(batch, Traversal::kOctomap, got, stats);
    sort_voxels(got);
    const VoxelList want = cpu_states(batch, Traversal::kOctomap);
    EXPECT_TRUE(same_voxels(got, want)) << "scan " << scan;
    EXPECT_EQ(stats.windows, 1u) << "scan " << scan;
    EXPECT_GT(stats.grid_words, 2048u);
    EXPECT_GE(stats.grid_words * 16, batch.keys.voxel_count());
    EXPECT_LT(stats.grid_words * 4, uint64_t(1) << 30) << "sized from the scan, not the budget";
    EXPECT_GE(stats.grid_allocations, allocations);
    if (scan == 0 && allocations) {
      EXPECT_EQ(stats.grid_allocations, allocations) << "a scan seen before: no growth";
    }
    allocations = stats.grid_allocations;
  }
}

TEST(VulkanRaySpace, ManyScansOneGridNothingLeftBehind) {
  // With max range the grid is sized to hold any scan in one window; over many scans the
  // grid is never re-allocated and every scan's touched words are exactly those read back
  // (a word left dirty by a previous scan would show up as an extra voxel).
  auto gpu = make_vulkan(0.1, 3.0);
  for (int round = 0; round < 2; ++round) {
    for (size_t scan = 0; scan < 6; ++scan) {
      const RayBatch batch = synthetic_batch(scan, 0.1, 3.0);
      VoxelList got;
      ShootStats stats;
      gpu->shoot(batch, Traversal::kOctomap, got, stats);
      sort_voxels(got);
      const VoxelList want = cpu_states(batch, Traversal::kOctomap);
      EXPECT_TRUE(same_voxels(got, want))
          << "scan " << scan << ": " << diff_voxels(got, want, batch, Traversal::kOctomap).substr(0, 2000);
      EXPECT_EQ(stats.windows, 1u);
      EXPECT_EQ(stats.grid_allocations, 1u);
      EXPECT_EQ(stats.words_read_back, stats.words_touched);
      // The grid holds the max-range cube, not the budget.
      EXPECT_LT(stats.grid_words * 4, uint64_t(1) << 20);
    }
  }
}

TEST(VulkanRaySpace, ChunkedCompactionWhenTouchedWordsExceedOnePass) {
  // An output of 64K voxels: one compact pass covers 4096 touched words, so a room scan's
  // compaction runs in many chunks (the automatic output holds 16M voxels or more).
  BackendOptions o;
  o.kind = BackendKind::kVulkan;
  o.resolution = 0.05;
  if (const char* d = std::getenv("OCTOMAP_RT_TEST_DEVICE")) o.device = d;
  VulkanTuning tuning;
  tuning.output_voxels = 1 << 16;
  auto gpu = make_vulkan_backend(o, tuning);
  for (Traversal mode : {Traversal::kOctomap, Traversal::kExact}) {
    const RayBatch batch = synthetic_batch(2, 0.05, -1.0, 3);
    VoxelList got;
    ShootStats stats;
    gpu->shoot(batch, mode, got, stats);
    sort_voxels(got);
    ASSERT_GT(stats.words_touched, 4u * 4096u) << "the scan does not exercise chunking";
    std::printf("%s: %llu words touched, 4096 a compact pass\n", to_string(mode),
                (unsigned long long)stats.words_touched);
    EXPECT_EQ(stats.words_read_back, stats.words_touched);
    const VoxelList want = cpu_states(batch, mode);
    EXPECT_TRUE(same_voxels(got, want)) << diff_voxels(got, want, batch, mode).substr(0, 2000);
  }
}

TEST(VulkanRaySpace, OccupiedWinsOverFreeInsideOneScan) {
  auto gpu = make_vulkan(0.1, -1.0, 1 << 20);
  const octomap::point3d origin(0.05f, 0.05f, 0.05f);
  // Ray 0 ends in voxel x = 2.0..2.1 (a hit); ray 1 passes through it to x = 5.05; ray 2
  // passes through both but is cut at max range 6 m (x = 6.05): free space only, and the
  // voxel at the cut end is not updated;
  // ray 3 ends (a hit) in the origin's own voxel: occupied, although every ray starts there.
  const std::vector<octomap::point3d> points = {
      {2.05f, 0.05f, 0.05f}, {5.05f, 0.05f, 0.05f}, {9.05f, 0.05f, 0.05f}, {0.07f, 0.06f, 0.04f}};
  for (Traversal mode : {Traversal::kOctomap, Traversal::kExact}) {
    PrepareReport report;
    const RayBatch batch = prepare_scan(origin, points, 6.0, 0.1, report);
    ASSERT_EQ(report.cut_at_max_range, 1u);
    VoxelList got;
    ShootStats stats;
    gpu->shoot(batch, mode, got, stats);
    sort_voxels(got);
    const VoxelList want = cpu_states(batch, mode);
    EXPECT_TRUE(same_voxels(got, want)) << diff_voxels(got, want, batch, mode);
    auto state_of = [&](int kx) -> int {
      for (const VoxelUpdate& v : got) {
        if (v.x == 32768 + kx && v.y == 32768 && v.z == 32768) return v.state;
      }
      return 0;
    };
    EXPECT_EQ(state_of(0), int(kStateOccupied)) << to_string(mode);  // ray 3's hit beats every ray's origin voxel
    EXPECT_EQ(state_of(1), int(kStateFree)) << to_string(mode);
    EXPECT_EQ(state_of(20), int(kStateOccupied)) << to_string(mode);  // ray 0's hit beats rays 1 and 2
    EXPECT_EQ(state_of(21), int(kStateFree)) << to_string(mode);
    EXPECT_EQ(state_of(50), int(kStateOccupied)) << to_string(mode);  // ray 1's hit
    EXPECT_EQ(state_of(49), int(kStateFree)) << to_string(mode);
    EXPECT_EQ(state_of(51), int(kStateFree)) << to_string(mode);  // ray 2 only, up to the cut
    EXPECT_EQ(state_of(59), int(kStateFree)) << to_string(mode);
    if (mode == Traversal::kOctomap) {
      EXPECT_EQ(state_of(60), 0);  // the cut end voxel: no update
    }
    EXPECT_EQ(state_of(61), 0) << to_string(mode);
    for (const VoxelUpdate& v : got) EXPECT_TRUE(v.state == kStateFree || v.state == kStateOccupied);
  }
}

TEST(VulkanRaySpace, EmptyScanGivesNothing) {
  auto gpu = make_vulkan(0.1);
  RayBatch batch;
  batch.origin = octomap::point3d(1, 2, 3);
  batch.resolution = 0.1;
  VoxelList got = {make_update(octomap::OcTreeKey(1, 2, 3), true)};
  ShootStats stats;
  gpu->shoot(batch, Traversal::kOctomap, got, stats);
  EXPECT_TRUE(got.empty());
  EXPECT_EQ(stats.words_touched, 0u);
  EXPECT_EQ(stats.grid_allocations, 1u);
}

TEST(RaySpaceSizing, MaxRangeCubeBudgetAndChunks) {
  // 10 m at 0.1 m: side 2 * (100 + 3) + 1 = 207 voxels.
  const auto a = gpu::size_ray_space(10.0, 0.1, 128u << 20, 128u << 20, 65535);
  EXPECT_EQ(a.grid_words, (207ull * 207 * 207 + 15) / 16);
  EXPECT_EQ(a.output_voxels, a.grid_words * 16);  // small grid: the output holds all of it
  EXPECT_EQ(a.chunk_words, a.grid_words);
  // No max range: the budget; the output is capped, compaction chunked.
  const auto b = gpu::size_ray_space(-1.0, 0.1, 128u << 20, 128u << 20, 65535);
  EXPECT_EQ(b.grid_words, (128u << 20) / 4);
  EXPECT_EQ(b.output_voxels, (128u << 20) / 8);
  EXPECT_EQ(uint64_t(b.chunk_words) * 16, b.output_voxels);
  // A max range whose cube exceeds the budget is capped by it (scans then use windows).
  const auto c = gpu::size_ray_space(100.0, 0.05, 1u << 20, 128u << 20, 65535);
  EXPECT_EQ(c.grid_words, (1u << 20) / 4);
  // Voxel indices stay 32-bit whatever the budget.
  const auto d = gpu::size_ray_space(-1.0, 0.1, uint64_t(8) << 30, uint64_t(4) << 30, 65535);
  EXPECT_LE(d.grid_words * 16, uint64_t(1) << 32);
  EXPECT_LE(d.chunk_words, 65535u * 256u);
  EXPECT_EQ(gpu::auto_grid_budget(128u << 20, uint64_t(16) << 30), 128u << 20);
  EXPECT_EQ(gpu::auto_grid_budget(uint64_t(4) << 30, uint64_t(80) << 30), uint64_t(1) << 30);
  EXPECT_EQ(gpu::auto_grid_budget(uint64_t(4) << 30, uint64_t(2) << 30), uint64_t(256) << 20);
}

bool overlap(const KeyBox& a, const KeyBox& b) {
  for (int i = 0; i < 3; ++i) {
    if (a.hi[i] < b.lo[i] || b.hi[i] < a.lo[i]) return false;
  }
  return true;
}

TEST(RaySpaceWindows, DisjointCoverWithinCapacity) {
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> key(0, 65535), extent(0, 400);
  for (int trial = 0; trial < 300; ++trial) {
    KeyBox keys;
    for (int i = 0; i < 3; ++i) {
      keys.lo[i] = key(rng);
      keys.hi[i] = std::min(65535, keys.lo[i] + extent(rng));
    }
    const uint64_t capacity = std::uniform_int_distribution<uint64_t>(1, 5000000)(rng);
    const std::vector<KeyBox> w = plan_windows(keys, capacity, 2);
    KeyBox wide;
    for (int i = 0; i < 3; ++i) {
      wide.lo[i] = std::max(0, keys.lo[i] - 2);
      wide.hi[i] = std::min(65535, keys.hi[i] + 2);
    }
    uint64_t covered = 0;
    for (size_t a = 0; a < w.size(); ++a) {
      ASSERT_FALSE(w[a].empty());
      ASSERT_LE(w[a].voxel_count(), capacity);
      for (int i = 0; i < 3; ++i) {
        ASSERT_GE(w[a].lo[i], wide.lo[i]);
        ASSERT_LE(w[a].hi[i], wide.hi[i]);
      }
      covered += w[a].voxel_count();
      if (w.size() < 300) {
        for (size_t b = a + 1; b < w.size(); ++b) ASSERT_FALSE(overlap(w[a], w[b]));
      }
    }
    ASSERT_EQ(covered, wide.voxel_count());  // disjoint + inside + same volume = exact cover
  }
  // A box 2.3 times the capacity along its long axis takes 3 windows, not 4.
  KeyBox k;
  k.lo[0] = k.lo[1] = k.lo[2] = 1000;
  k.hi[0] = 1000 + 225;
  k.hi[1] = k.hi[2] = 1000 + 5;
  EXPECT_EQ(plan_windows(k, 230 * 10 * 10 / 2.3 + 1, 2).size(), 3u);
  EXPECT_TRUE(plan_windows(KeyBox{}, 100).empty());
}

}  // namespace
}  // namespace ort::test
