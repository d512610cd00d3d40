// Read-your-writes with real processes in a network namespace (docs/PROTOCOL.md, "Queries"):
// a robot publishes scan k over udpm to octomap-rt-server and at once asks, through the
// client library, about the end points of that scan with wait_robot_id / wait_seq = k. The
// answer must come from the map that contains scan k: every state equal to OctoMap's own map
// after scans 0..k, and the end points occupied. Each scan is shifted into space no earlier
// scan saw, so an answer that did not wait finds its end points unknown.
#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>

#include "cli/replay/scan_message.h"
#include "core/clock.h"
#include "integration_harness.h"
#include "octomap_rt/occupancy_reply_t.hpp"
#include "query/point_query.h"
#include "query_client/query_client.h"
#include "scene/scan_set.h"
#include "support/test_data.h"

namespace ort::test {
namespace {

using Reply = octomap_rt::occupancy_reply_t;

// At most `most` of the scan's end points in the map frame (every n-th), as x, y, z floats.
std::vector<float> end_points(const PosedScan& scan, size_t most) {
  const octomap::Pointcloud world = world_points(scan);
  const size_t stride = (world.size() + most - 1) / most;
  std::vector<float> xyz;
  for (size_t i = 0; i < world.size(); i += stride) xyz.insert(xyz.end(), {world[i].x(), world[i].y(), world[i].z()});
  return xyz;
}

TEST(QueryIntegration, ARobotSeesItsOwnScanRightAfterSendingIt) {
  const std::string graph = data_file("3dtk_dat/3dtk_3scans.graph");
  if (graph.empty()) return;
  const ScanSet scans = load_scan_graph(graph);
  NetworkNamespace ns("ryw");
  ASSERT_TRUE(ns.ok()) << ns.error();
  const std::string dir = make_test_dir("ryw");
  const std::string url = test_lcm_url(4, ns.rmem_max());
  const std::string client_url = url.substr(0, url.find("&recv_buf_size"));
  StatusWatcher status(url);
  const double res = 0.2;
  ChildProcess server({server_program(), "--lcm-url", url, "-r", std::to_string(res)}, dir + "/server.log");
  ASSERT_TRUE(status.wait_for([&](const auto& s) { return s.pid == server.pid(); }, 60)) << server.log();

  lcm::LCM robot(client_url);
  ASSERT_TRUE(robot.good());
  client::QueryClient queries(client_url, "rover-planner", std::chrono::seconds(60));
  octomap::OcTree reference(res);
  constexpr int kScans = 6;
  for (int k = 0; k < kScans; ++k) {
    PosedScan scan = scans.scans[k % scans.scans.size()];
    scan.pose.trans().x() += 100.0f * static_cast<float>(k);  // space no earlier scan saw
    cli::ScanMessageFields fields;
    fields.robot_id = "rover", fields.seq = k, fields.utime = now_utime();
    const octomap_rt::scan_t msg = cli::make_scan_message(scan, fields);
    robot.publish(cli::scan_channel(ort::protocol::kScanChannelPrefix, "rover"), &msg);
    const std::vector<float> xyz = end_points(scan, 5000);
    client::WaitFor wait;
    wait.robot_id = "rover", wait.seq = k, wait.timeout_ms = 30000;
    const Reply r = queries.points(xyz, 0, wait);  // sent right after the scan
    ASSERT_EQ(r.status, Reply::REPLY_OK) << r.error;
    EXPECT_EQ(r.snapshot_id, k + 1) << "one robot: scan k makes map state k + 1";

    reference.insertPointCloud(world_points(scan), sensor_origin(scan), -1.0, false, false);
    const std::vector<query::PointAnswer> want = query::query_points(reference, xyz, 0);
    ASSERT_EQ(r.num_results, static_cast<int32_t>(want.size()));
    int differing = 0, occupied = 0;
    for (size_t i = 0; i < want.size(); ++i) {
      differing += r.occupancy[i] != int8_t(want[i].state) || r.probability[i] != want[i].probability;
      occupied += r.occupancy[i] == Reply::OCC_OCCUPIED;
    }
    EXPECT_EQ(differing, 0) << "scan " << k << ": answers differ from OctoMap's map after scans 0.." << k;
    EXPECT_GT(occupied, static_cast<int>(0.95 * want.size()))
        << "scan " << k << ": " << occupied << " of " << want.size() << " end points occupied";
  }
  server.signal(SIGTERM);
  EXPECT_EQ(server.wait(120), 0) << server.log();
}

}  // namespace
}  // namespace ort::test
