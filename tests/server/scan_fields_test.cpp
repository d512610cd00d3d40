// Issue 21, item 1, in the whole server over memq:// on every back end (GPU ones where a
// device exists, else skipped): one scan per degenerate value of each numeric field of
// scan_t, from one robot. Each is refused with its own reason, or applied with the points
// that cannot be walked counted; the server keeps running and its map is OctoMap's of the
// valid scans. Before the fix, the degenerate rays crashed the cpu and cpu-grid back ends.
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
#include "support/tree_compare.h"

namespace ort::test {
namespace {

using daemon::Reject;
using M = octomap_rt::scan_t;

int64_t count(const std::array<int64_t, daemon::kRejectReasonCount>& a, Reject r) { return a[static_cast<size_t>(r)]; }

// A scan from a sensor at the map's origin (on a voxel border on all three axes), identity
// orientation: ordinary points around it, points with coordinates below 1e-20 m (subnormals
// among them), which the scan contract reads as 0, and points nearer than 1e-15 m to it
// across a border, which it skips (core/prepare_scan.h). `expected`: the points as read.
PosedScan scan_at_zero(std::vector<octomap::point3d>& expected) {
  PosedScan s;
  s.pose = octomap::pose6d(0, 0, 0, 0, 0, 0);
  for (int i = 0; i < 24; ++i) {
    s.points.push_back({1.5f, 0.1f * float(i - 12), 0.05f * float(i % 5)});
    expected.push_back(s.points.back());
  }
  const std::pair<octomap::point3d, octomap::point3d> tiny[] = {
      {{-1e-30f, 0, 0}, {0, 0, 0}}, {{0, -1e-25f, 1e-30f}, {0, 0, 0}}, {{1e-30f, 0.35f, -1.4e-45f}, {0, 0.35f, 0}}};
  for (const auto& [p, read] : tiny) {
    s.points.push_back(p);
    expected.push_back(read);
  }
  for (const octomap::point3d& p : {octomap::point3d(-1e-19f, 0, 0), octomap::point3d(3e-20f, -5e-16f, 2e-18f)})
    s.points.push_back(p);
  return s;
}

class ScanFields : public ::testing::TestWithParam<BackendKind> {};

TEST_P(ScanFields, EveryDegenerateFieldIsRefusedWithItsReasonOrWalkedSafely) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
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
  const std::string ch = "OCTOMAP_RT_SCAN_FIELDS";
  int64_t seq = 0, sent = 0;
  auto publish = [&](M m) {  // consecutive seqs unless the scan sets its own
    if (m.seq == 0) m.seq = seq;
    ++seq;
    lc.publish(ch, &m);
    ++sent;
  };
  auto changed = [&](auto change) {
    M m = small_scan("fields", 0);
    change(m);
    publish(m);
  };
  // Refused, each with its reason.
  changed([](M& m) { m.max_range = 1e-30f; });
  changed([](M& m) { m.max_range = 1.4e-45f; });
  changed([](M& m) { m.max_range = std::numeric_limits<float>::infinity(); });
  changed([](M& m) { m.sensor_position[0] = 1e300; });
  changed([](M& m) { m.sensor_position[1] = -1e39; });
  changed([](M& m) { m.sensor_position[2] = std::numeric_limits<double>::quiet_NaN(); });
  changed([](M& m) { m.sensor_orientation[0] = 1e300; });
  changed([](M& m) {
    m.sensor_orientation[0] = m.sensor_orientation[1] = m.sensor_orientation[2] = m.sensor_orientation[3] = 1e-300;
  });
  changed([](M& m) { m.points_frame = -128; });
  // Applied: degenerate rays skipped (map frame and sensor frame), points beyond the key
  // range skipped, extreme seq and utime values.
  std::vector<octomap::point3d> read_map, read_sensor;
  M in_map = scan_message(scan_at_zero(read_map), "fields", 0);
  in_map.points_frame = M::POINTS_IN_MAP_FRAME;
  publish(in_map);
  publish(scan_message(scan_at_zero(read_sensor), "fields", 0));
  changed([](M& m) {
    m.xyz[0] = 3e38f, m.xyz[4] = -3e38f;  // beyond the key range (in the sensor frame: rotated, still beyond)
    m.utime = std::numeric_limits<int64_t>::min();
  });
  changed([](M& m) { m.utime = std::numeric_limits<int64_t>::max(); });
  const int64_t last = seq;
  changed([last](M& m) { m.seq = std::numeric_limits<int64_t>::max() - last; });  // a restart, not 2^63 lost
  changed([](M& m) { m.max_range = 0.5f; });  // a short max range: cut rays, free only

  ASSERT_TRUE(wait_until_done(*server, sent));
  const auto stats = server->producer_stats();
  expect_counts_balance(stats);
  ASSERT_EQ(stats.size(), 1u);
  const auto& r = stats[0].rejects;
  EXPECT_EQ(count(r, Reject::kMaxRangeTooSmall), 2);
  EXPECT_EQ(count(r, Reject::kBadMaxRange), 1);
  EXPECT_EQ(count(r, Reject::kOriginOutsideMap), 2);
  EXPECT_EQ(count(r, Reject::kNonFinitePose), 1);
  EXPECT_EQ(count(r, Reject::kNonUnitQuaternion), 1);
  EXPECT_EQ(count(r, Reject::kZeroQuaternion), 1);
  EXPECT_EQ(count(r, Reject::kUnknownPointsFrame), 1);
  EXPECT_EQ(stats[0].rejected, 9);
  EXPECT_EQ(stats[0].applied, sent - 9);
  EXPECT_GE(stats[0].seq_restarts, 1);
  EXPECT_LT(stats[0].missed, 1000);
  EXPECT_EQ(stats[0].point_drops[static_cast<size_t>(daemon::PointDrop::kDegenerateRay)], 4);  // 2 a scan
  // The tiny coordinates read as 0 are in the status the operator reads (3 points a scan).
  const auto status = server->status();
  ASSERT_EQ(status.robots.size(), 1u);
  EXPECT_EQ(status.robots[0].points_read_as_zero, 6);

  // OctoMap's map of the applied scans, without the points it cannot walk (and without those
  // outside the key range, which it skips, saying so on stderr).
  octomap::OcTree ref(0.1);
  EngineOptions exact_options;
  exact_options.resolution = 0.1;
  exact_options.backend.kind = BackendKind::kCpu;
  exact_options.traversal = Traversal::kExact;
  MapEngine exact(exact_options);
  auto insert = [&](const M& m, const std::vector<octomap::point3d>* only, double max_range) {
    const octomap::pose6d pose(float(m.sensor_position[0]), float(m.sensor_position[1]), float(m.sensor_position[2]), 0,
                               0, 0);
    octomap::pose6d p(pose.trans(),
                      octomath::Quaternion(float(m.sensor_orientation[0]), float(m.sensor_orientation[1]),
                                           float(m.sensor_orientation[2]), float(m.sensor_orientation[3])));
    octomap::Pointcloud cloud;
    if (only) {
      for (const auto& q : *only) cloud.push_back(q);
    } else {
      for (size_t i = 0; i + 2 < m.xyz.size(); i += 3) cloud.push_back(m.xyz[i], m.xyz[i + 1], m.xyz[i + 2]);
      if (m.points_frame == M::POINTS_IN_SENSOR_FRAME) cloud.transform(p);
    }
    octomap::Pointcloud inside;
    octomap::OcTreeKey key;
    for (const auto& q : cloud)
      if (ref.coordToKeyChecked(q, key)) inside.push_back(q);
    if (cfg.engine.traversal == Traversal::kOctomap)
      return ref.insertPointCloud(inside, p.trans(), max_range, false, false);
    ShotScan shot;
    exact.shoot(p.trans(), std::span<const octomap::point3d>(&inside[0], inside.size()), max_range, shot);
    exact.apply(shot, ref);
  };
  insert(in_map, &read_map, -1);
  insert(in_map, &read_sensor, -1);
  M far = small_scan("fields", 0);
  far.xyz[0] = 3e38f, far.xyz[4] = -3e38f;
  insert(far, nullptr, -1);
  insert(small_scan("fields", 0), nullptr, -1);
  insert(small_scan("fields", 0), nullptr, -1);
  insert(small_scan("fields", 0), nullptr, 0.5);
  server->with_map([&](const octomap::OcTree& tree) {
    const TreeDiff d = compare_leaves(tree, ref);
    EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels differ: " << d.first_difference;
  });
  server->stop();
}

INSTANTIATE_TEST_SUITE_P(EveryBackEnd, ScanFields, kEveryBackend, backend_param_name);

}  // namespace
}  // namespace ort::test
