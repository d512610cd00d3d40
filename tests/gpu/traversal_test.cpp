// The `vulkan` back end against the CPU references, scan by scan, with few rays a scan so a
// wrong voxel points at its ray: OctoMap's own computeRayKeys (octomap mode) and the
// independent exact CPU reference (exact mode), at least 10^5 random rays each.
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "core/prepare_scan.h"
#include "gpu/gpu_test_support.h"
#include "gpu/random_rays.h"

namespace ort::test {
namespace {

constexpr uint64_t kMinRays = 100000;

void check_random_rays(Traversal mode) {
  const uint64_t seed = test_seed();
  std::mt19937_64 rng(seed + (mode == Traversal::kExact ? 1 : 0));
  // One back end for every resolution: the batch carries its own. A small budget keeps
  // lavapipe's start-up clear of the grid short.
  auto gpu = make_vulkan(0.1, -1.0, 16u << 20);
  uint64_t rays = 0, scans = 0, voxels = 0, failures = 0, differing = 0;
  std::map<std::string, uint64_t> rays_by_kind;
  while (rays < kMinRays) {
    const RandomScan s = random_scan(rng);
    PrepareReport report;
    const RayBatch batch = prepare_scan(s.origin, s.points, s.max_range, s.resolution, report);
    if (!report.origin_ok) continue;
    VoxelList got;
    ShootStats stats;
    gpu->shoot(batch, mode, got, stats);
    sort_voxels(got);
    const VoxelList want = reference_states(batch, mode);
    const bool same = same_voxels(got, want);
    differing += same ? 0 : 1;
    if (!same && failures < 5) {
      ++failures;
      ADD_FAILURE() << to_string(mode) << " scan " << scans << " (" << s.kind << ", seed " << seed
                    << "): " << diff_voxels(got, want, batch, mode);
    }
    ASSERT_EQ(stats.words_read_back, stats.words_touched);
    rays += batch.ends.size();
    rays_by_kind[s.kind] += batch.ends.size();
    voxels += want.size();
    ++scans;
  }
  EXPECT_EQ(differing, 0u);
  std::string kinds;
  for (const auto& [k, n] : rays_by_kind) kinds += " " + k + "=" + std::to_string(n);
  std::printf("%s: %llu rays in %llu scans, %llu voxels, %llu scans differ from the reference (seed %llu);%s\n",
              to_string(mode), (unsigned long long)rays, (unsigned long long)scans, (unsigned long long)voxels,
              (unsigned long long)differing, (unsigned long long)seed, kinds.c_str());
  for (const char* k : {"axis", "face", "corner", "short", "key_edge", "far", "max_range", "random"}) {
    EXPECT_GT(rays_by_kind[k], 1000u) << k;
  }
}

TEST(VulkanTraversal, OctomapModeEqualsComputeRayKeys) { check_random_rays(Traversal::kOctomap); }

TEST(VulkanTraversal, ExactModeEqualsExactReference) { check_random_rays(Traversal::kExact); }

}  // namespace
}  // namespace ort::test
