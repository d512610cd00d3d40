// Issue 24, item 1: octomap_server's filters in the server: pass-through limits in the map
// frame (its pointcloud_min/max_x/y/z) and in the sensor frame, a min range beside the max
// range. A real scan (octomap_share/scan_dat.graph) streamed over memq:// with each filter
// set; the map equals OctoMap's insertPointCloud of the cloud filtered here by hand (the same
// rules written out again: PCL PassThrough's min <= v <= max, OctoMap's float distance), and
// every removed point is counted for the robot under its rule.
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "server/scan_fixtures.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct FilterCase {
  const char* name;
  double map_lo[3], map_hi[3];        // pointcloud_min/max_x/y/z
  double sensor_lo[3], sensor_hi[3];  // the sensor-frame box
  double min_range, max_range;
  BackendKind backend;
  bool map_frame_message;  // points sent in the map frame (the sensor box then goes back by the inverse pose)
};

bool inside(const octomap::point3d& p, const double lo[3], const double hi[3]) {
  for (int i = 0; i < 3; ++i)
    if (!(double(p(i)) >= lo[i] && double(p(i)) <= hi[i])) return false;
  return true;
}

class PointFiltersTest : public ::testing::TestWithParam<FilterCase> {};

TEST_P(PointFiltersTest, TheMapIsOctoMapsOfTheCloudFilteredByHand) {
  const FilterCase& c = GetParam();
  const ScanSet set = load_scan_graph(data_file("octomap_share/scan_dat.graph"));
  ASSERT_EQ(set.scans.size(), 1u);
  PosedScan scan;
  scan.pose = octomap::pose6d(0.5f, -1.0f, 0.4f, 0.01, -0.02, 0.3);
  for (size_t i = 0; i < set.scans[0].points.size(); i += 2) scan.points.push_back(set.scans[0].points[i]);

  // By hand: the sensor box on the points as sent, the map box on OctoMap's transform of them,
  // the min range on OctoMap's float distance from the sensor; the first rule failed counts.
  octomap::Pointcloud world = scan.points;
  world.transform(scan.pose);
  const octomap::point3d origin = scan.pose.trans();
  octomap::Pointcloud kept;
  int64_t out_sensor = 0, out_map = 0, near = 0;
  const octomap::pose6d inverse = scan.pose.inv();
  for (size_t i = 0; i < world.size(); ++i) {
    const octomap::point3d s = c.map_frame_message ? inverse.transform(world[i]) : scan.points[i];
    if (!inside(s, c.sensor_lo, c.sensor_hi)) {
      ++out_sensor;
    } else if (!inside(world[i], c.map_lo, c.map_hi)) {
      ++out_map;
    } else if (c.min_range > 0 && (world[i] - origin).norm() < c.min_range) {
      ++near;
    } else {
      kept.push_back(world[i]);
    }
  }
  ASSERT_GT(kept.size(), 1000u);
  ASSERT_GT(out_sensor + out_map + near, 1000) << "the filters must remove something to test";
  octomap::OcTree ref(0.2);
  ref.insertPointCloud(kept, origin, c.max_range, false, false);

  lcm::LCM lc("memq://");
  auto cfg = test_config(0.2, true);
  cfg.engine.backend.kind = c.backend;
  cfg.engine.backend.threads = 2;
  cfg.engine.max_range = c.max_range;
  for (int i = 0; i < 3; ++i) {
    cfg.point_filters.map_frame.min[i] = c.map_lo[i], cfg.point_filters.map_frame.max[i] = c.map_hi[i];
    cfg.point_filters.sensor_frame.min[i] = c.sensor_lo[i], cfg.point_filters.sensor_frame.max[i] = c.sensor_hi[i];
  }
  cfg.point_filters.min_range = c.min_range;
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  server.start();
  octomap_rt::scan_t m = scan_message(scan, "filtered", 0);
  if (c.map_frame_message) {
    m.points_frame = octomap_rt::scan_t::POINTS_IN_MAP_FRAME;
    m.xyz.clear();
    for (const auto& p : world) m.xyz.insert(m.xyz.end(), {p.x(), p.y(), p.z()});
  }
  lc.publish("OCTOMAP_RT_SCAN_FILTERED", &m);
  ASSERT_TRUE(wait_until_done(server, 1));
  const auto st = server.status();
  ASSERT_EQ(st.robots.size(), 1u);
  const auto& r = st.robots[0];
  EXPECT_EQ(r.scans_applied, 1);
  EXPECT_EQ(r.points_applied, int64_t(kept.size()));
  std::map<std::string, int64_t> drops;
  for (size_t i = 0; i < r.point_drop_reason.size(); ++i) drops[r.point_drop_reason[i]] = r.point_drop_count[i];
  std::map<std::string, int64_t> want;
  if (out_sensor) want["outside sensor-frame box"] = out_sensor;
  if (out_map) want["outside map-frame box"] = out_map;
  if (near) want["below min range"] = near;
  EXPECT_EQ(drops, want);
  server.with_map([&](const octomap::OcTree& tree) {
    const TreeDiff d = compare_leaves(tree, ref);
    EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels differ: " << d.first_difference;
  });
  server.stop();
}

INSTANTIATE_TEST_SUITE_P(OctomapServersFilters, PointFiltersTest,
                         ::testing::Values(
                             // octomap_server's usual height band (pointcloud_min_z / max_z) and an x limit, map frame.
                             FilterCase{"map_frame_box",
                                        {-1, -kInf, 0.2},
                                        {12, kInf, 2.0},
                                        {-kInf, -kInf, -kInf},
                                        {kInf, kInf, kInf},
                                        0,
                                        -1,
                                        BackendKind::kCpu,
                                        false},
                             // The robot's own body in front of the sensor: a box in the sensor frame.
                             FilterCase{"sensor_frame_box",
                                        {-kInf, -kInf, -kInf},
                                        {kInf, kInf, kInf},
                                        {1.5, -kInf, -kInf},
                                        {kInf, 6, kInf},
                                        0,
                                        -1,
                                        BackendKind::kCpu,
                                        false},
                             // A min range beside OctoMap's max range (cut rays, free only).
                             FilterCase{"min_and_max_range",
                                        {-kInf, -kInf, -kInf},
                                        {kInf, kInf, kInf},
                                        {-kInf, -kInf, -kInf},
                                        {kInf, kInf, kInf},
                                        2.5,
                                        8.0,
                                        BackendKind::kCpu,
                                        false},
                             // All of them, points sent in the map frame, on the cpu-grid back end.
                             FilterCase{"all_map_frame_message_cpu_grid",
                                        {-1, -kInf, 0.2},
                                        {12, kInf, 2.0},
                                        {1.5, -kInf, -kInf},
                                        {kInf, 6, kInf},
                                        2.5,
                                        8.0,
                                        BackendKind::kCpuGrid,
                                        true}),
                         [](const auto& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace ort::test
