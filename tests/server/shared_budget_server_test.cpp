// The shared class's budget (intake/shared_class_budget.h) in the whole server over memq://:
// while a robot with history streams, scans from fresh ids whose rays reach farther than any
// scan the daemon applied (100 points 400 m out: ~0.8 M new nodes each at 0.1 m, ~650 ms of
// stage 1 each on the H200) are refused before they are shot, each counted as "predicted too
// slow" on its producer, and none grows the map; every robot scan applies. With the budget off
// (only the share of session 7) the same burst applies far scans: the test can fail.
#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

using daemon::Reject;

struct BudgetRun {
  int64_t attacks = 20, robot_sent = 0, robot_applied = 0, robot_received = 0;
  int64_t attacker_received = 0, attacker_applied = 0, attacker_too_slow = 0, attacker_over_share = 0;
  int64_t nodes_before = 0, nodes_after = 0;
};

int64_t others_resolved(daemon::MappingServer& server, const std::string& robot) {
  int64_t n = 0;
  for (const auto& p : server.producer_stats())
    if (p.robot_id != robot) n += p.applied + p.rejected + p.dropped;
  return n;
}

BudgetRun run_far_burst(bool budget) {
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.scan_costs.share_history_scans = 5;  // the robot earns its share within the test
  cfg.scan_costs.share_history_s = 0.2;
  cfg.scan_costs.max_scan_stage_s = 0;  // the budget's bound alone, not --max-scan-time
  cfg.scan_costs.shared.enabled = budget;
  daemon::MappingServer server(cfg, lc, std::cerr);
  server.start();
  BudgetRun r;
  int64_t seq = 0;
  auto robot_scan = [&] {
    const auto s = reaching_scan(seq, {1.f + 0.01f * float(seq), 2, 0.5f}, 8, 300);
    seq++;
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &s);
    r.robot_sent++;
  };
  for (int k = 0; k < 5; ++k) robot_scan();
  EXPECT_TRUE(wait_until_done(server, r.robot_sent));
  std::this_thread::sleep_for(std::chrono::milliseconds(250));
  robot_scan();  // the robot has history and streams when the burst arrives
  EXPECT_TRUE(wait_until_done(server, r.robot_sent));
  r.nodes_before = server.status().num_nodes;
  for (int64_t k = 0; k < r.attacks; ++k) {
    auto far = reaching_scan(k, {1, 2, 0.5f}, 400, 100);  // 4000 voxels a ray: under the mean-ray bound
    far.robot_id = "FRESH" + std::to_string(k);
    lc.publish("OCTOMAP_RT_SCAN_" + far.robot_id, &far);
  }
  // At 10 Hz until every far scan has left (bounded: 60 s).
  while (others_resolved(server, "ALPHA") < r.attacks && r.robot_sent < 600) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    robot_scan();
  }
  EXPECT_TRUE(wait_until_done(server, r.robot_sent + r.attacks, std::chrono::seconds(300)));
  r.nodes_after = server.status().num_nodes;
  server.stop();
  const auto stats = server.producer_stats();
  expect_counts_balance(stats);
  for (const auto& p : stats) {
    if (p.robot_id == "ALPHA") {
      r.robot_received = p.received;
      r.robot_applied = p.applied;
      continue;
    }
    r.attacker_received += p.received;
    r.attacker_applied += p.applied;
    r.attacker_too_slow += p.rejects[static_cast<size_t>(Reject::kPredictedTooSlow)];
    r.attacker_over_share += p.drop_reasons[static_cast<size_t>(Reject::kOverShare)];
  }
  std::cerr << "budget " << budget << ": robot applied " << r.robot_applied << " of " << r.robot_received
            << "; attacker applied " << r.attacker_applied << ", predicted too slow " << r.attacker_too_slow
            << ", over its share " << r.attacker_over_share << "; nodes " << r.nodes_before << " -> " << r.nodes_after
            << "\n";
  return r;
}

TEST(SharedBudget, FarScansOfUnknownCostFromFreshIdsAreRefusedWhileARobotStreams) {
  const BudgetRun r = run_far_burst(true);
  EXPECT_EQ(r.robot_received, r.robot_sent);
  EXPECT_EQ(r.robot_applied, r.robot_received);
  EXPECT_EQ(r.attacker_received, r.attacks);
  EXPECT_EQ(r.attacker_applied, 0);
  EXPECT_EQ(r.attacker_too_slow, r.attacks);  // each counted with its reason, none lost silently
  // The robot's own scans add a few thousand nodes; one far scan would add ~0.8 M.
  EXPECT_LT(r.nodes_after - r.nodes_before, 200'000);
}

TEST(SharedBudget, WithoutTheBudgetTheSameBurstGrowsTheMap) {
  const BudgetRun r = run_far_burst(false);
  EXPECT_EQ(r.attacker_received, r.attacks);
  EXPECT_GT(r.attacker_applied, 0);
  EXPECT_EQ(r.attacker_too_slow, 0);
  EXPECT_GT(r.nodes_after - r.nodes_before, 200'000);
}

}  // namespace
}  // namespace ort::test
