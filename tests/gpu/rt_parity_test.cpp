// The `rt` back end (ray-tracing pipeline) against the `vulkan` compute back end and the
// exact CPU reference, in exact mode: >= 10^5 random rays (axis-aligned, in faces, through
// edges and corners, zero-length, near the key edge, cut at max range) and the real data
// sets, with the default block grid and with a small one that forces many windows.
//
// Where the device has no ray tracing (lavapipe in CI), the clean refusal is what is tested
// and the GPU comparisons are skipped.
#include <array>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/prepare_scan.h"
#include "engine/backend_factory.h"
#include "gpu/gpu_test_support.h"
#include "gpu/random_rays.h"
#include "gpu/rt/rt_ray_backend.h"
#include "scene/scan_set.h"
#include "support/test_data.h"

namespace ort::test {
namespace {

bool same(const VoxelList& a, const VoxelList& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].x != b[i].x || a[i].y != b[i].y || a[i].z != b[i].z || a[i].state != b[i].state) return false;
  }
  return true;
}

BackendOptions rt_options(double res, double max_range, Traversal mode = Traversal::kExact) {
  BackendOptions o;
  o.kind = BackendKind::kRt;
  o.traversal = mode;
  o.resolution = res;
  o.max_range = max_range;
  if (const char* d = std::getenv("OCTOMAP_RT_TEST_DEVICE")) o.device = d;
  return o;
}

// The rt back end, or nullptr with the refusal in *why.
std::unique_ptr<RayBackend> try_rt(double res, double max_range, const rt::RtOptions& knobs, std::string* why,
                                   rt::RtBvhInfo* info = nullptr) {
  try {
    return rt::make_rt_backend(rt_options(res, max_range), knobs, Log{}, info);
  } catch (const std::exception& e) {
    *why = e.what();
    return nullptr;
  }
}

std::unique_ptr<RayBackend> try_vulkan(double res, double max_range) {
  try {
    return make_vulkan(res, max_range);
  } catch (const std::exception& e) {
    std::printf("vulkan back end not available (%s): comparing with the CPU reference only\n", e.what());
    return nullptr;
  }
}

TEST(RtBackend, RefusesOctomapModeClearly) {
  try {
    rt::make_rt_backend(rt_options(0.1, -1.0, Traversal::kOctomap), rt::RtOptions{});
    FAIL() << "rt accepted --traversal octomap";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("unsupported:", 0), 0u) << m;
    EXPECT_NE(m.find("exact only"), std::string::npos) << m;
  }
}

TEST(RtBackend, IsMadeOrRefusedCleanly) {
  std::string why;
  auto rt = try_rt(0.1, -1.0, rt::RtOptions{}, &why);
  if (rt) {
    std::printf("rt back end available on %s\n", rt->device_name().c_str());
    EXPECT_EQ(rt->kind(), BackendKind::kRt);
    return;
  }
  std::printf("rt refused: %s\n", why.c_str());
  EXPECT_EQ(why.rfind("unsupported:", 0), 0u) << why;
  // The message names what is missing (the device's own list from the Vulkan layer).
  EXPECT_NE(why.find("VK_KHR_ray_tracing_pipeline"), std::string::npos) << why;
  EXPECT_NE(why.find("VK_KHR_acceleration_structure"), std::string::npos) << why;
  // And the automatic choice moves on instead of failing.
  BackendOptions o = rt_options(0.1, -1.0);
  o.kind = BackendKind::kAuto;
  std::string log;
  auto any = make_backend(o, log_into(log));
  ASSERT_TRUE(any);
  EXPECT_NE(any->kind(), BackendKind::kRt);
  EXPECT_NE(log.find("rt back end not used: unsupported"), std::string::npos) << log;
}

TEST(RtBackend, RandomRaysEqualExactReferenceAndVulkan) {
  std::string why;
  auto rt = try_rt(0.1, -1.0, rt::RtOptions{}, &why);
  if (!rt) GTEST_SKIP() << why;
  auto vk = try_vulkan(0.1, -1.0);
  const uint64_t seed = test_seed();
  std::mt19937_64 rng(seed + 5);
  uint64_t rays = 0, scans = 0, failures = 0, vk_failures = 0;
  std::map<std::string, uint64_t> by_kind;
  while (rays < 100000) {
    const RandomScan s = random_scan(rng);
    PrepareReport report;
    const RayBatch batch = prepare_scan(s.origin, s.points, s.max_range, s.resolution, report);
    if (!report.origin_ok) continue;
    VoxelList got;
    ShootStats stats;
    rt->shoot(batch, Traversal::kExact, got, stats);
    sort_voxels(got);
    const VoxelList want = reference_states(batch, Traversal::kExact);
    if (!same(got, want) && ++failures <= 5) {
      ADD_FAILURE() << "scan " << scans << " (" << s.kind << ", seed " << seed
                    << "): " << diff_voxels(got, want, batch, Traversal::kExact);
    }
    ASSERT_EQ(stats.words_read_back, stats.words_touched);
    if (vk) {
      VoxelList other;
      ShootStats vs;
      vk->shoot(batch, Traversal::kExact, other, vs);
      sort_voxels(other);
      if (!same(other, got) && ++vk_failures <= 5) {
        ADD_FAILURE() << "rt != vulkan on scan " << scans << " (" << s.kind << ")";
      }
    }
    rays += batch.ends.size();
    by_kind[s.kind] += batch.ends.size();
    ++scans;
  }
  EXPECT_EQ(failures, 0u);
  EXPECT_EQ(vk_failures, 0u);
  std::string kinds;
  for (const auto& [k, n] : by_kind) kinds += " " + k + "=" + std::to_string(n);
  std::printf("rt exact: %llu rays in %llu scans equal to the exact reference%s (seed %llu);%s\n",
              (unsigned long long)rays, (unsigned long long)scans, vk ? " and to vulkan" : "", (unsigned long long)seed,
              kinds.c_str());
  for (const char* k : {"axis", "face", "corner", "short", "key_edge", "far", "max_range"})
    EXPECT_GT(by_kind[k], 1000u) << k;
}

struct RealCase {
  const char* file;
  double resolution;
  double max_range;
};

std::vector<RayBatch> real_batches(const RealCase& c) {
  const std::string path = data_file(c.file);
  std::vector<RayBatch> out;
  if (path.empty()) return out;
  const ScanSet set = load_scan_graph(path);
  for (const PosedScan& s : set.scans) {
    const octomap::Pointcloud world = world_points(s);
    const std::vector<octomap::point3d> pts(world.begin(), world.end());
    PrepareReport report;
    out.push_back(prepare_scan(sensor_origin(s), pts, c.max_range, c.resolution, report));
  }
  return out;
}

void compare_on_real_data(const rt::RtOptions& knobs, bool check_reference_on_first) {
  const RealCase cases[] = {{"3dtk_dat/3dtk_3scans.graph", 0.1, -1.0},
                            {"3dtk_dat/3dtk_3scans.graph", 0.2, -1.0},
                            {"3dtk_dat/3dtk_3scans.graph", 0.1, 10.0},
                            {"octomap_share/scan_dat.graph", 0.1, -1.0},
                            {"octomap_share/scan_dat.graph", 0.1, 10.0}};
  for (const RealCase& c : cases) {
    std::string why;
    rt::RtBvhInfo info;
    auto rt = try_rt(c.resolution, c.max_range, knobs, &why, &info);
    if (!rt) GTEST_SKIP() << why;
    auto vk = try_vulkan(c.resolution, c.max_range);
    int scan = 0;
    for (const RayBatch& batch : real_batches(c)) {
      VoxelList got;
      ShootStats stats;
      rt->shoot(batch, Traversal::kExact, got, stats);
      sort_voxels(got);
      EXPECT_EQ(stats.words_read_back, stats.words_touched);
      const bool with_reference = !vk || (check_reference_on_first && scan == 0);
      if (with_reference) {
        const VoxelList want = reference_states(batch, Traversal::kExact);
        EXPECT_TRUE(same(got, want)) << c.file << " @" << c.resolution << " scan " << scan << ": "
                                     << diff_voxels(got, want, batch, Traversal::kExact);
      }
      bool equal_vk = false;
      if (vk) {
        VoxelList other;
        ShootStats vs;
        vk->shoot(batch, Traversal::kExact, other, vs);
        sort_voxels(other);
        equal_vk = same(got, other);
        EXPECT_TRUE(equal_vk) << c.file << " @" << c.resolution << " scan " << scan << ": rt " << got.size()
                              << " voxels, vulkan " << other.size();
      }
      std::printf(
          "%s res %.2f max_range %.0f scan %d: %zu rays, %zu voxels, %llu window(s), k=%d block grid %dx%dx%d%s\n",
          c.file, c.resolution, c.max_range, scan, batch.ends.size(), got.size(), (unsigned long long)stats.windows,
          info.block_grid.block, info.block_grid.voxels(0), info.block_grid.voxels(1), info.block_grid.voxels(2),
          equal_vk ? ", equal to vulkan" : (vk ? ", DIFFERENT from vulkan" : ""));
      ++scan;
    }
  }
}

TEST(RtBackend, RealDataEqualsVulkan) { compare_on_real_data(rt::RtOptions{}, true); }

TEST(RtBackend, RealDataInManySmallWindowsEqualsVulkan) {
  rt::RtOptions small;
  small.block = 2;
  small.wanted[0] = 96;
  small.wanted[1] = 64;
  small.wanted[2] = 32;
  compare_on_real_data(small, false);
}

}  // namespace
}  // namespace ort::test

namespace ort::test {
namespace {

// Single rays that lie in voxel faces, printed in full: the rt list against the exact
// reference, with the default BVH, with every traversal candidate marked (no exact test),
// and with wide AABB margins. Asserts equality for the default; prints the rest.
TEST(RtBackend, FaceRaysInDetail) {
  struct Case {
    const char* name;
    double res;
    octomap::point3d origin;
    std::vector<octomap::point3d> ends;
  };
  const Case cases[] = {
      {"along -y in faces x=42,z=23", 1.0, {42.0f, 4.38980627f, 23.0f}, {{42.0f, 2.8411088f, 23.0f}}},
      {"same, window lowered", 1.0, {42.0f, 4.38980627f, 23.0f}, {{42.0f, 2.8411088f, 23.0f}, {30.5f, 1.5f, 10.5f}}},
      {"along -y from the origin", 0.1, {0.0f, 0.0f, 0.0f}, {{0.0f, -0.913f, 0.0f}}},
      {"along +z in faces x=-16,y=5", 0.5, {-16.0f, 5.0f, 4.0f}, {{-16.0f, 5.0f, 18.1849651f}}},
  };
  struct Variant {
    const char* name;
    float margin;
    bool candidates;
  };
  const Variant variants[] = {{"default", rt::kAabbMargin, false},
                              {"candidates", rt::kAabbMargin, true},
                              {"margin 0.25", 0.25f, false},
                              {"margin 0.25 candidates", 0.25f, true}};
  for (const Variant& v : variants) {
    rt::RtOptions knobs;
    knobs.aabb_margin = v.margin;
    knobs.mark_candidates = v.candidates;
    std::string why;
    auto rt = try_rt(0.1, -1.0, knobs, &why);
    if (!rt) GTEST_SKIP() << why;
    for (const Case& c : cases) {
      PrepareReport report;
      const RayBatch batch = prepare_scan(c.origin, c.ends, -1.0, c.res, report);
      VoxelList got;
      ShootStats stats;
      rt->shoot(batch, Traversal::kExact, got, stats);
      sort_voxels(got);
      const VoxelList want = reference_states(batch, Traversal::kExact);
      std::printf("[%s] %s: window lo (%d %d %d), rt %zu voxels, reference %zu\n", v.name, c.name, batch.keys.lo[0] - 1,
                  batch.keys.lo[1] - 1, batch.keys.lo[2] - 1, got.size(), want.size());
      auto key = [](const VoxelUpdate& u) { return std::array<int, 3>{u.x, u.y, u.z}; };
      std::map<std::array<int, 3>, int> seen;
      for (const auto& u : got) seen[key(u)] |= 1;
      for (const auto& u : want) seen[key(u)] |= 2;
      int shown = 0;
      for (const auto& [k, m] : seen) {
        if (m == 3 || ++shown > 6) continue;
        std::printf("    %s (%d %d %d)\n", m == 1 ? "extra  " : "missing", k[0], k[1], k[2]);
      }
      if (!v.candidates && v.margin == rt::kAabbMargin) {
        EXPECT_TRUE(same(got, want)) << c.name;
      }
    }
  }
}

}  // namespace
}  // namespace ort::test
