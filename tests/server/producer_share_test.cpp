// The stages' time shared among producers (issue 21, intake/scan_queue.h), in the whole
// server over memq://: an attacker who knows the mean-ray bound sends scans that just pass it
// (100 points 400 m out: ~0.8 M new nodes each at 0.1 m) from a fresh robot id each time,
// faster than the stages can apply them, while a robot with history streams. With one FIFO
// the robot's scans waited behind them past the latency bound and were shed; with the share
// every robot scan is applied within the bound and the attacker's are dropped as "over its
// share", counted per producer.
#include <chrono>
#include <map>
#include <thread>

#include <gtest/gtest.h>

#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

using daemon::Reject;

TEST(ProducerShare, FarScansFromFreshIdsDoNotTakeAStreamingRobotsTurn) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.latency_bound_s = 5;                 // the default
  cfg.scan_costs.share_history_scans = 5;  // the robot earns its share within the test
  cfg.scan_costs.share_history_s = 0.2;
  daemon::MappingServer server(cfg, lc, std::cerr);
  server.start();
  int64_t seq = 0, sent = 0;
  auto robot_scan = [&] {
    const auto s = reaching_scan(seq, {1.f + 0.01f * float(seq), 2, 0.5f}, 8, 300);
    seq++;
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
    sent++;
  };
  for (int k = 0; k < 5; ++k) robot_scan();
  ASSERT_TRUE(wait_until_done(server, sent));
  std::this_thread::sleep_for(std::chrono::milliseconds(250));
  const int64_t attacks = 20;
  for (int64_t k = 0; k < attacks; ++k) {
    robot_scan();
    auto far = reaching_scan(k, {1, 2, 0.5f}, 400, 100);  // 4000 voxels a ray: under the mean-ray bound
    far.robot_id = "FRESH" + std::to_string(k);
    lc.publish("OCTOMAP_RT_SCAN_" + far.robot_id, &far);
    sent++;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_TRUE(wait_until_done(server, sent, std::chrono::seconds(300)));
  server.stop();
  const auto stats = server.producer_stats();
  expect_counts_balance(stats);
  int64_t attacker_applied = 0, attacker_over_share = 0, attacker_received = 0;
  const daemon::ProducerStats* robot = nullptr;
  for (const auto& p : stats) {
    if (p.robot_id == "ALPHA") {
      robot = &p;
      continue;
    }
    attacker_received += p.received;
    attacker_applied += p.applied;
    attacker_over_share += p.drop_reasons[static_cast<size_t>(Reject::kOverShare)];
  }
  ASSERT_NE(robot, nullptr);
  EXPECT_EQ(robot->received, 5 + attacks);
  // Every robot scan applied: none waited past the latency bound (5 s; shed when it does).
  EXPECT_EQ(robot->applied, robot->received)
      << "dropped over latency bound: " << robot->drop_reasons[static_cast<size_t>(Reject::kOverLatencyBound)]
      << ", over its share: " << robot->drop_reasons[static_cast<size_t>(Reject::kOverShare)];
  EXPECT_EQ(attacker_received, attacks);
  EXPECT_LT(attacker_applied, attacks);
  EXPECT_GT(attacker_over_share, 0);
  std::cerr << "robot applied " << robot->applied << " of " << robot->received << "; attacker applied "
            << attacker_applied << ", over its share " << attacker_over_share << " of " << attacks << "\n";
}

}  // namespace
}  // namespace ort::test
