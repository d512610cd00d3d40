// The long-lived map in the daemon (daemon/map/map_upkeep.h): scans go in over memq://, decay
// steps and clearing passes are taken between them, and the map that comes out is the one the
// engine and the documented rules (octree/decay.h, octree/distance_clearing.h, each checked
// against OctoMap's own tree in forgetting_test) give in the same order. With the upkeep's own
// thread and clock, a map no robot sees any more decays to nothing and its nodes are freed.
#include <chrono>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "engine/map_engine.h"
#include "octree/decay.h"
#include "octree/distance_clearing.h"
#include "scene/synthetic_scene.h"
#include "server/scan_fixtures.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

void send_and_wait(lcm::LCM& lc, daemon::MappingServer& server, const octomap_rt::scan_t& msg, int64_t total) {
  lc.publish("OCTOMAP_RT_SCAN_" + std::string(msg.robot_id == "alpha" ? "ALPHA" : "BETA"), &msg);
  ASSERT_TRUE(wait_until_done(server, total));
}

TEST(MapUpkeep, DecayStepsBetweenScansGiveTheRulesMap) {
  auto cfg = test_config(0.1, true);
  cfg.upkeep.decay_half_life_s = 10;
  cfg.upkeep.decay_step_s = 5;
  cfg.upkeep.manual = true;
  cfg.upkeep.slice_nodes = 500;  // many slices a step
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  const ScanSet scene = make_synthetic_rooms();
  MapEngine engine(cfg.engine);
  auto reference = engine.make_tree();
  const DecayRule one{decay_factor(5, 10), 0.1f}, two{decay_factor(10, 10), 0.1f};
  int64_t sent = 0;
  for (size_t k = 0; k < 4 && k < scene.scans.size(); ++k) {
    send_and_wait(lc, server, scan_message(scene.scans[k], "alpha", int64_t(k)), ++sent);
    ShotScan shot;
    engine.insert_posed(scene.scans[k].pose, sensor_origin(scene.scans[k]),
                        std::span<const octomap::point3d>(&scene.scans[k].points[0], scene.scans[k].points.size()),
                        *reference, shot);
    server.upkeep()->decay_steps(k % 2 ? 2 : 1);
    decay_tree(*reference, region_grid(10), k % 2 ? two : one);
    server.with_map([&](const octomap::OcTree& t) { EXPECT_EQ(compare_structure(*reference, t), "") << "scan " << k; });
    // The read replica replays the slices: what snapshots and saves read is the same map.
    server.with_readable_map(
        [&](const octomap::OcTree& t) { EXPECT_EQ(compare_structure(*reference, t), "") << "replica, scan " << k; });
  }
  ASSERT_TRUE(server.replica_stats().has_value()) << "the server runs with its read replica while decay is on";
  const auto st = server.upkeep()->stats();
  EXPECT_EQ(st.decay_steps, 6u);
  EXPECT_EQ(st.decay_sweeps, 4u);
  EXPECT_GT(st.slices, 8u);
  EXPECT_GT(st.nodes_deleted_by_decay, 0u);
  server.stop();
}

TEST(MapUpkeep, ClearingKeepsWhatIsNearTheRobotsSeenLately) {
  auto cfg = test_config(0.1, true);
  cfg.upkeep.clear_radius_m = 2.5;
  cfg.upkeep.clear_recent_s = 600;
  cfg.upkeep.manual = true;
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  const ScanSet scene = make_synthetic_rooms();
  MapEngine engine(cfg.engine);
  auto reference = engine.make_tree();
  std::vector<octomap::point3d> last_origin(2);
  for (size_t k = 0; k < 4 && k < scene.scans.size(); ++k) {
    const std::string robot = k % 2 ? "beta" : "alpha";
    send_and_wait(lc, server, scan_message(scene.scans[k], robot, int64_t(k)), int64_t(k) + 1);
    ShotScan shot;
    engine.insert_posed(scene.scans[k].pose, sensor_origin(scene.scans[k]),
                        std::span<const octomap::point3d>(&scene.scans[k].points[0], scene.scans[k].points.size()),
                        *reference, shot);
    last_origin[k % 2] = sensor_origin(scene.scans[k]);
  }
  const size_t before = reference->size();
  server.upkeep()->clear_now();
  clear_beyond(*reference, region_grid(10), last_origin, 2.5);
  EXPECT_LT(reference->size(), before);
  server.with_map([&](const octomap::OcTree& t) { EXPECT_EQ(compare_structure(*reference, t), ""); });
  server.with_readable_map(
      [&](const octomap::OcTree& t) { EXPECT_EQ(compare_structure(*reference, t), "") << "replica"; });
  EXPECT_GT(server.upkeep()->stats().nodes_deleted_by_clearing, 0u);
  server.stop();
}

TEST(MapUpkeep, UnseenMapDecaysToNothingOnTheDaemonsClock) {
  auto cfg = test_config(0.1, true);
  cfg.upkeep.decay_half_life_s = 0.1;  // 3.5 -> below 0.1 in ~0.52 s
  cfg.upkeep.decay_step_s = 0.02;
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  const ScanSet scene = make_synthetic_rooms();
  for (size_t k = 0; k < 3; ++k) {
    const auto msg = scan_message(scene.scans[k], "alpha", int64_t(k));
    lc.publish("OCTOMAP_RT_SCAN_ALPHA", &msg);
  }
  ASSERT_TRUE(wait_until_done(server, 3));
  size_t nodes = 1;
  for (int i = 0; i < 400 && nodes > 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
    nodes = server.with_map([](const octomap::OcTree& t) { return t.size(); });
  }
  EXPECT_EQ(nodes, 0u);
  server.with_map([](const octomap::OcTree& t) { EXPECT_EQ(t.getRoot(), nullptr); });
  server.with_readable_map([](const octomap::OcTree& t) { EXPECT_EQ(t.size(), 0u); });
  const auto st = server.upkeep()->stats();
  EXPECT_GT(st.decay_steps, 20u);
  EXPECT_GT(st.nodes_deleted_by_decay, 0u);
  server.stop();
}

}  // namespace
}  // namespace ort::test
