// GPU preparation (gpu/gpu_prepare.h, shaders/prepare_rays.comp) against the CPU's
// (engine/map_frame.h transform + engine/prepare_scan.h), ray for ray and bit for bit:
// random poses and points with NaN/inf, far points, points on both sides of the max-range
// boundary, and the real scans of ../shared/data. Then the engine both ways: same voxels,
// same map.
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <span>
#include <vector>

#include <gtest/gtest.h>

#include "core/map_frame.h"
#include "core/prepare_scan.h"
#include "engine/map_engine.h"
#include "gpu/gpu_prepare.h"
#include "gpu/vk/vk_buffer.h"
#include "gpu/vk/vk_context.h"
#include "gpu_test_support.h"
#include "scene/scan_set.h"
#include "support/test_data.h"

namespace ort {
namespace {

using Points = std::vector<octomap::point3d>;
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

struct Scan {
  octomap::pose6d pose;
  octomap::point3d origin;
  Points points;  // sensor frame
  double max_range = -1.0;
  double resolution = 0.1;
};

uint32_t bits(float f) {
  uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
}

class GpuPrepareTest : public ::testing::Test {
 protected:
  void SetUp() override {
    vk::ContextOptions co;
    if (const char* d = std::getenv("OCTOMAP_RT_TEST_DEVICE")) co.device = d;
    ctx_ = std::make_shared<vk::Context>(co);
    prepare_ = std::make_unique<gpu::GpuPrepare>(ctx_);
  }

  // The GPU's rays with the dropped ones left out, and what it reported.
  std::vector<RayEnd> gpu_rays(const Scan& s, gpu::DevicePrepared& result) {
    const VkDeviceSize bytes = std::max<size_t>(1, s.points.size()) * sizeof(RayEnd);
    if (!rays_ || rays_bytes_ < bytes) {
      rays_ = vk::Buffer(*ctx_, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                         VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
      rays_bytes_ = bytes;
    }
    prepare_->stage_points(as_xyz(s.points));
    result = prepare_->run({s.pose, s.origin, s.max_range, s.resolution}, rays_.handle());
    rays_.invalidate();
    std::vector<RayEnd> kept;
    const RayEnd* all = rays_.as<RayEnd>();
    for (size_t i = 0; i < s.points.size(); ++i) {
      if (!(all[i].flags & kRayEndDropped)) kept.push_back(all[i]);
    }
    return kept;
  }

  // Compares GPU and CPU preparation of one scan; returns the CPU's report.
  PrepareReport check(const Scan& s, const std::string& what) {
    Points world = s.points;
    transform_to_map_frame(std::span<octomap::point3d>(world), s.pose, 1);
    PrepareReport want_report;
    const RayBatch want = prepare_scan(s.origin, world, s.max_range, s.resolution, want_report, 1);
    EXPECT_TRUE(want_report.origin_ok) << what;
    gpu::DevicePrepared got;
    const std::vector<RayEnd> rays = gpu_rays(s, got);
    EXPECT_EQ(got.nonfinite, want_report.nonfinite) << what;
    EXPECT_EQ(got.out_of_range, want_report.out_of_range) << what;
    EXPECT_EQ(got.cut_at_max_range, want_report.cut_at_max_range) << what;
    EXPECT_EQ(got.degenerate, want_report.degenerate) << what;
    EXPECT_EQ(got.read_as_zero,
              want_report.read_as_zero + tiny_as_sent_only(as_xyz(s.points), std::span<const octomap::point3d>(world)))
        << what;
    EXPECT_EQ(rays.size(), want.ends.size()) << what;
    size_t differ = 0;
    for (size_t i = 0; i < std::min(rays.size(), want.ends.size()); ++i) {
      const RayEnd& g = rays[i];
      const RayEnd& w = want.ends[i];
      if (std::memcmp(&g, &w, sizeof g) == 0) continue;
      if (++differ <= 5) {
        ADD_FAILURE() << what << ": ray " << i << " GPU (" << g.x << ", " << g.y << ", " << g.z << ", " << g.flags
                      << ") bits " << std::hex << bits(g.x) << " " << bits(g.y) << " " << bits(g.z) << ", CPU ("
                      << std::dec << w.x << ", " << w.y << ", " << w.z << ", " << w.flags << ") bits " << std::hex
                      << bits(w.x) << " " << bits(w.y) << " " << bits(w.z);
      }
    }
    EXPECT_EQ(differ, 0u) << what;
    KeyBox keys = got.end_keys;
    keys.include(want.origin_key);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(keys.lo[i], want.keys.lo[i]) << what;
      EXPECT_EQ(keys.hi[i], want.keys.hi[i]) << what;
    }
    return want_report;
  }

  std::shared_ptr<vk::Context> ctx_;
  std::unique_ptr<gpu::GpuPrepare> prepare_;
  vk::Buffer rays_;
  VkDeviceSize rays_bytes_ = 0;
};

octomap::pose6d random_pose(std::mt19937& rng) {
  std::uniform_real_distribution<double> t(-60.0, 60.0), a(-M_PI, M_PI);
  return octomap::pose6d(t(rng), t(rng), t(rng), a(rng), a(rng), a(rng));
}

// Mostly ordinary points; some with NaN or inf coordinates, some far beyond the key range
// or large enough to overflow |d|^2, some tiny (subnormals among them: read as 0 as sent).
Points random_points(std::mt19937& rng, size_t n) {
  std::uniform_real_distribution<float> near(-40.0f, 40.0f), u(0.0f, 1.0f);
  const float odd[] = {kNan, kInf, -kInf, 1e4f, -4e3f, 1e20f, 3e38f, -3e38f, 1e-30f, 0.0f, -0.0f, 1e-39f, -5e-21f};
  Points pts(n);
  for (auto& p : pts) {
    p = octomap::point3d(near(rng), near(rng), near(rng));
    if (u(rng) < 0.05f) p(std::uniform_int_distribution<int>(0, 2)(rng)) = odd[rng() % std::size(odd)];
  }
  return pts;
}

TEST_F(GpuPrepareTest, RandomPosesAndPointsMatchTheCpuBitForBit) {
  std::mt19937 rng(12);
  const double ranges[] = {-1.0, 0.0, 5.0, 12.5, 30.0, 1e30};
  const double resolutions[] = {0.1, 0.05, 0.2, 0.08};
  uint64_t nonfinite = 0, out_of_range = 0, cut = 0;
  for (int k = 0; k < 24; ++k) {
    Scan s;
    s.pose = random_pose(rng);
    s.origin = s.pose.trans();
    s.points = random_points(rng, 20000 + k * 997);
    s.max_range = ranges[k % std::size(ranges)];
    s.resolution = resolutions[k % std::size(resolutions)];
    const PrepareReport r = check(s, "scan " + std::to_string(k));
    nonfinite += r.nonfinite;
    out_of_range += r.out_of_range;
    cut += r.cut_at_max_range;
  }
  EXPECT_GT(nonfinite, 0u);  // the cases this test is about did occur
  EXPECT_GT(out_of_range, 0u);
  EXPECT_GT(cut, 0u);
}

// Points whose OctoMap norm lies within a few ulps of max range, on both sides.
TEST_F(GpuPrepareTest, MaxRangeBoundaryMatchesTheCpu) {
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0.0f, 1.0f);
  for (double max_range : {5.0, 7.3, 0.1, 29.999999}) {
    Scan s;
    s.pose = octomap::pose6d(1.5, -2.25, 0.75, 0, 0, 0);
    s.origin = s.pose.trans();
    s.max_range = max_range;
    for (int d = 0; d < 2000; ++d) {
      octomap::point3d dir(g(rng), g(rng), g(rng));
      dir.normalize();
      const octomap::point3d at = dir * float(max_range);  // sensor frame: the origin is the pose's translation
      for (int step = -6; step <= 6; ++step) {
        octomap::point3d p = at;
        for (int i = 0; i < 3; ++i) {
          for (int n = 0; n < std::abs(step); ++n) p(i) = std::nextafter(p(i), step > 0 ? 2 * p(i) : 0.0f);
        }
        s.points.push_back(p);
      }
    }
    const PrepareReport r = check(s, "max range " + std::to_string(max_range));
    EXPECT_GT(r.cut_at_max_range, 0u);
    EXPECT_LT(r.cut_at_max_range, s.points.size());
  }
}

TEST(GpuPrepareLimit, NormSqLimitIsOctomapsTest) {
  std::mt19937 rng(3);
  for (double m : {0.0, 0.1, 5.0, 7.3, 29.999999, 1e30, 1e300}) {
    const float limit = gpu::norm_sq_limit(m);
    for (int k = -50; k <= 50; ++k) {
      float f = limit;
      for (int n = 0; n < std::abs(k); ++n) f = std::nextafter(f, k > 0 ? kInf : 0.0f);
      EXPECT_EQ(f <= limit, std::sqrt(double(f)) <= m) << "max range " << m << ", |d|^2 " << f;
    }
  }
  EXPECT_EQ(gpu::norm_sq_limit(std::numeric_limits<double>::quiet_NaN()), -1.0f);
  EXPECT_EQ(gpu::norm_sq_limit(std::numeric_limits<double>::infinity()), kInf);
}

TEST_F(GpuPrepareTest, RealScansMatchTheCpuBitForBit) {
  for (const char* graph : {"3dtk_dat/3dtk_3scans.graph", "octomap_share/scan_dat.graph"}) {
    const ScanSet set = load_scan_graph(test::data_file(graph));
    for (size_t i = 0; i < set.scans.size(); ++i) {
      for (double max_range : {-1.0, 10.0}) {
        Scan s;
        s.pose = set.scans[i].pose;
        s.origin = sensor_origin(set.scans[i]);
        s.points.assign(set.scans[i].points.begin(), set.scans[i].points.end());
        s.max_range = max_range;
        check(s, std::string(graph) + " scan " + std::to_string(i) + " max range " + std::to_string(max_range));
      }
    }
  }
}

// The engine with GPU preparation and without: the same voxel states and the same map, with
// dropped points (NaN, far) among real ones so that the shooting passes skip them.
TEST(GpuPrepareEngine, SameVoxelsAndMapAsCpuPreparation) {
  const ScanSet set = load_scan_graph(test::data_file("3dtk_dat/3dtk_3scans.graph"));
  auto make = [](bool gpu_prepare, Traversal t) {
    EngineOptions o;
    o.resolution = 0.1;
    o.max_range = 15.0;
    o.traversal = t;
    o.backend.kind = BackendKind::kVulkan;
    o.backend.gpu_prepare = gpu_prepare;
    if (const char* d = std::getenv("OCTOMAP_RT_TEST_DEVICE")) o.backend.device = d;
    return std::make_unique<MapEngine>(o);
  };
  for (Traversal t : {Traversal::kOctomap, Traversal::kExact}) {
    auto on = make(true, t), off = make(false, t);
    ASSERT_TRUE(on->backend().prepares_on_device());
    ASSERT_FALSE(off->backend().prepares_on_device());
    auto tree_on = on->make_tree(), tree_off = off->make_tree();
    for (const PosedScan& scan : set.scans) {
      Points pts(scan.points.begin(), scan.points.end());
      pts.insert(pts.begin() + pts.size() / 2, {{kNan, 0, 0}, {1e6f, 0, 0}, {0, -kInf, 1}});
      ShotScan a, b;
      on->insert_posed(scan.pose, sensor_origin(scan), pts, *tree_on, a);
      off->insert_posed(scan.pose, sensor_origin(scan), pts, *tree_off, b);
      EXPECT_EQ(a.prepare.rays, b.prepare.rays);
      EXPECT_EQ(a.prepare.nonfinite, 2u);
      EXPECT_EQ(a.prepare.out_of_range, b.prepare.out_of_range);
      EXPECT_EQ(a.prepare.cut_at_max_range, b.prepare.cut_at_max_range);
      EXPECT_GT(a.prepare.cut_at_max_range, 0u);
      test::sort_voxels(a.voxels);
      test::sort_voxels(b.voxels);
      EXPECT_TRUE(test::same_voxels(a.voxels, b.voxels)) << to_string(t);
    }
    EXPECT_EQ(tree_on->size(), tree_off->size());
    EXPECT_TRUE(tree_on->operator==(*tree_off)) << to_string(t);
  }
}

}  // namespace
}  // namespace ort
