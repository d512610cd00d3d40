// Issue 13 in the whole server, in one process over memq://: a far-flung valid scan does not
// wedge it (finding 1), what OctoMap cannot walk is rejected with a reason, stale scans are
// shed under overload with a reason (overload policy), and --allow-robot keeps other
// channels out (finding 10).
#include <atomic>
#include <random>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

using daemon::Reject;

int64_t count(const std::array<int64_t, daemon::kRejectReasonCount>& a, Reject r) { return a[static_cast<size_t>(r)]; }

// `n` points `distance` metres from a sensor at (1, 2, 0.5), in random directions.
octomap_rt::scan_t far_scan(const std::string& robot, int64_t seq, double distance, int n) {
  std::mt19937 rng(static_cast<unsigned>(seq) + 3);
  std::normal_distribution<double> g(0.0, 1.0);
  PosedScan s;
  s.pose = octomap::pose6d(1.0f, 2.0f, 0.5f, 0.0, 0.0, 0.0);
  for (int i = 0; i < n; ++i) {
    const double d[3] = {g(rng), g(rng), g(rng)};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    s.points.push_back(float(d[0] / len * distance), float(d[1] / len * distance), float(d[2] / len * distance));
  }
  return scan_message(s, robot, seq);
}

TEST(ServerHardening, FarFlungScansDoNotWedgeTheServer) {
  auto cfg = test_config(0.1, true);
  cfg.engine.backend.kind = BackendKind::kCpuGrid;
  cfg.engine.backend.threads = 2;
  cfg.scan_costs.max_origin_jump_m = 0;    // the corner scan's origin jumps: this test is about its rays,
  cfg.scan_costs.max_mean_ray_voxels = 0;  // which are kilometres long (the engine's bounds, not the daemon's)
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  const std::string ch = "OCTOMAP_RT_SCAN_FAR";
  lc.publish(ch, &static_cast<const octomap_rt::scan_t&>(far_scan("far", 0, 3000.0, 50)));
  // Corner to corner of the key range: longer than OctoMap's ray walk can hold.
  octomap_rt::scan_t corner = small_scan("far", 1, 1);
  corner.sensor_position[0] = corner.sensor_position[1] = corner.sensor_position[2] = -3200.0;
  corner.points_frame = octomap_rt::scan_t::POINTS_IN_MAP_FRAME;
  corner.xyz = {3200.0f, 3200.0f, 3200.0f};
  lc.publish(ch, &corner);
  lc.publish(ch, &static_cast<const octomap_rt::scan_t&>(small_scan("far", 2, 30)));
  ASSERT_TRUE(wait_until_done(server, 3));
  const auto stats = server.producer_stats();
  expect_counts_balance(stats);
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].applied, 2);
  EXPECT_EQ(count(stats[0].rejects, Reject::kRayTooLong), 1);
  server.stop();
}

TEST(ServerHardening, StaleScansAreShedWithAReasonUnderOverload) {
  auto cfg = test_config(0.1, true);
  cfg.latency_bound_s = 0.001;
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  // Hold the map lock: stage 2 cannot apply, stage 1 stops after one shot, the queue fills
  // and its scans grow old.
  MapHold hold(server);
  const int n = 12;
  for (int k = 0; k < n; ++k)
    lc.publish("OCTOMAP_RT_SCAN_BUSY", &static_cast<const octomap_rt::scan_t&>(small_scan("busy", k, 30)));
  while (server.producer_stats().empty() || server.producer_stats()[0].received < n)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // every queued scan is now older than the bound
  hold.release();
  ASSERT_TRUE(wait_until_done(server, n));
  const auto stats = server.producer_stats();
  expect_counts_balance(stats);
  // At most the scan in stage 1 and the one in the hand-off were taken before they aged.
  EXPECT_GE(count(stats[0].drop_reasons, Reject::kOverLatencyBound), n - 3);
  EXPECT_EQ(stats[0].dropped, count(stats[0].drop_reasons, Reject::kOverLatencyBound));
  const auto status = server.status();
  ASSERT_EQ(status.robots.size(), 1u);
  ASSERT_EQ(status.robots[0].num_drop_reasons, 1);
  EXPECT_EQ(status.robots[0].drop_reason[0], "over latency bound");
  server.stop();
}

TEST(ServerHardening, OnlyAllowedRobotsAreServed) {
  auto cfg = test_config(0.1, true);
  cfg.allowed_robots = {"husky1"};
  cfg.max_producers = 1;
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  for (int i = 0; i < 5; ++i) {
    const std::string id = "intruder" + std::to_string(i);
    std::string ch = "OCTOMAP_RT_SCAN_" + id;
    for (char& c : ch) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    lc.publish(ch, &static_cast<const octomap_rt::scan_t&>(small_scan(id, 0, 10)));
  }
  lc.publish("OCTOMAP_RT_SCAN_HUSKY1", &static_cast<const octomap_rt::scan_t&>(small_scan("husky1", 0, 10)));
  ASSERT_TRUE(wait_until_done(server, 6));
  int64_t refused = 0, applied = 0;
  for (const auto& p : server.producer_stats()) {
    refused += count(p.rejects, Reject::kRobotNotAllowed);
    if (p.channel == "OCTOMAP_RT_SCAN_HUSKY1") applied = p.applied;
  }
  EXPECT_EQ(refused, 5);
  EXPECT_EQ(applied, 1);
  server.stop();
}

}  // namespace
}  // namespace ort::test
