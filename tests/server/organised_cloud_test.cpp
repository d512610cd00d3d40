// Issue 24, item 1: scans as drivers send them. An organised cloud (Ouster, Velodyne, depth
// cameras) is a range image: one point per pixel, NaN where the sensor got no return. Made
// here from OctoMap's own real scan (octomap_share/scan_dat.graph) projected into a 360 x 96
// image, streamed to the server over memq:// from two poses: every finite point is applied,
// every NaN counted per producer ("non-finite"), no scan refused, and the map equals OctoMap's
// insertPointCloud of the finite points, leaf by leaf, on every back end (GPU ones where a
// device exists; rt, exact traversal only, against the cpu back end's exact walk).
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "engine/map_engine.h"
#include "server/scan_fixtures.h"
#include "support/every_backend.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

constexpr int kColumns = 360, kRows = 96;
constexpr double kResolution = 0.2;

// The scan as a range image: pixel (row, column) by elevation and azimuth, the first point of
// each pixel kept, NaN (all three coordinates) where no point falls.
std::vector<octomap::point3d> range_image(const octomap::Pointcloud& scan) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<octomap::point3d> image(kColumns * kRows, octomap::point3d(nan, nan, nan));
  double el_lo = 1e9, el_hi = -1e9;
  for (const auto& p : scan) {
    const double el = std::atan2(p.z(), std::hypot(p.x(), p.y()));
    el_lo = std::min(el_lo, el), el_hi = std::max(el_hi, el);
  }
  for (const auto& p : scan) {
    const double az = std::atan2(p.y(), p.x()), el = std::atan2(p.z(), std::hypot(p.x(), p.y()));
    const int col = std::min(kColumns - 1, int((az + M_PI) / (2 * M_PI) * kColumns));
    const int row = std::min(kRows - 1, int((el - el_lo) / (el_hi - el_lo) * kRows));
    octomap::point3d& px = image[row * kColumns + col];
    if (std::isnan(px.x())) px = p;
  }
  return image;
}

class OrganisedCloud : public ::testing::TestWithParam<BackendKind> {};

TEST_P(OrganisedCloud, NaNNoReturnsAreCountedEveryFinitePointAppliedAndTheMapIsOctoMaps) {
  const ScanSet set = load_scan_graph(data_file("octomap_share/scan_dat.graph"));
  ASSERT_EQ(set.scans.size(), 1u);
  const std::vector<octomap::point3d> image = range_image(set.scans[0].points);
  size_t finite = 0;
  for (const auto& p : image) finite += std::isfinite(p.x()) ? 1 : 0;
  const size_t no_returns = image.size() - finite;
  ASSERT_GT(finite, image.size() / 4);
  ASSERT_GT(no_returns, image.size() / 10) << "the image must have no-returns to count";

  lcm::LCM lc("memq://");
  auto cfg = test_config(kResolution, true);
  cfg.engine.backend.kind = GetParam();
  cfg.engine.traversal = reference_traversal(GetParam());
  cfg.engine.backend.grid_budget_bytes = 64ull << 20;
  cfg.engine.backend.threads = 2;
  std::ostringstream log;
  std::unique_ptr<daemon::MappingServer> server;
  try {
    server = std::make_unique<daemon::MappingServer>(cfg, lc, log);
  } catch (const Unsupported& e) {
    GTEST_SKIP() << "no device for " << to_string(GetParam()) << ": " << e.what();
  }
  server->start();
  // The driver's cloud as it comes, in the sensor frame, from two poses.
  const std::vector<octomap::pose6d> poses = {octomap::pose6d(0.5f, -1.0f, 0.3f, 0.0, 0.0, 0.2),
                                              octomap::pose6d(2.0f, 0.5f, 0.4f, 0.02, -0.01, -0.4)};
  std::vector<PosedScan> sent;
  for (size_t i = 0; i < poses.size(); ++i) {
    PosedScan s;
    s.pose = poses[i];
    for (const auto& p : image) s.points.push_back(p);
    octomap_rt::scan_t m = scan_message(s, "ouster", int64_t(i));
    lc.publish("OCTOMAP_RT_SCAN_OUSTER", &m);
    sent.push_back(s);
  }
  ASSERT_TRUE(wait_until_done(*server, int64_t(poses.size())));

  const octomap_rt::server_status_t st = server->status();
  ASSERT_EQ(st.robots.size(), 1u);
  const auto& r = st.robots[0];
  EXPECT_EQ(r.scans_applied, int64_t(poses.size()));
  EXPECT_EQ(r.scans_rejected, 0);
  EXPECT_EQ(r.points_applied, int64_t(poses.size() * finite));
  ASSERT_EQ(r.num_point_drop_reasons, 1);
  EXPECT_EQ(r.point_drop_reason[0], "non-finite");
  EXPECT_EQ(r.point_drop_count[0], int64_t(poses.size() * no_returns));

  // OctoMap's insertPointCloud of the finite points, moved by each pose as OctoMap moves them.
  octomap::OcTree ref(kResolution);
  EngineOptions exact_options;
  exact_options.resolution = kResolution;
  exact_options.backend.kind = BackendKind::kCpu;
  exact_options.traversal = Traversal::kExact;
  MapEngine exact(exact_options);
  for (const PosedScan& s : sent) {
    octomap::Pointcloud finite_points;
    for (const auto& p : s.points)
      if (std::isfinite(p.x())) finite_points.push_back(p);
    finite_points.transform(s.pose);
    if (cfg.engine.traversal == Traversal::kOctomap) {
      ref.insertPointCloud(finite_points, s.pose.trans(), -1.0, false, false);
    } else {
      ShotScan shot;
      exact.shoot(s.pose.trans(), std::span<const octomap::point3d>(&finite_points[0], finite_points.size()), -1.0,
                  shot);
      exact.apply(shot, ref);
    }
  }
  server->with_map([&](const octomap::OcTree& tree) {
    const TreeDiff d = compare_leaves(tree, ref);
    EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels differ: " << d.first_difference;
    EXPECT_GT(tree.size(), 1000u);
  });
  server->stop();
}

INSTANTIATE_TEST_SUITE_P(EveryBackEnd, OrganisedCloud, kEveryBackend, backend_param_name);

}  // namespace
}  // namespace ort::test
