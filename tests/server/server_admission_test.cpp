// A producer's limits in the whole server over memq://: its queue's byte budget (the newest
// scans dropped, counted), the producer slots (the rest share "*", rejected), the warm-up's
// size, and the drain at stop (queued scans applied, not lost).
#include <algorithm>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "server/memq_producers.h"
#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

using daemon::Reject;

// The warm-up scan is never larger than the largest scan the daemon accepts.
TEST(ServerMemq, WarmUpIsNoLargerThanMaxPoints) {
  auto cfg = test_config(0.1, true);
  cfg.warm_up_points = 640 * 480;
  cfg.max_points = 1000;
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  server.stop();
  EXPECT_NE(log.str().find("warmed up on a scan of 1000 points"), std::string::npos) << log.str();
}

// A producer over its byte budget loses its newest scans, counted as dropped; what is
// applied keeps the arrival order, and the counts still balance.
TEST(ServerMemq, FullQueueDropsNewestAndCountsIt) {
  const auto scans = robot_scans(1, 6, 1);
  auto cfg = test_config(0.05, true);
  cfg.max_points = 30'000;
  cfg.queue_budget_bytes = 12 * 30'000 + 8192;  // about one full scan per producer
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  const auto& list = scans.at("robot0");
  const int rounds = 5;
  for (int round = 0; round < rounds; ++round)
    for (size_t k = 0; k < list.size(); ++k) {
      const auto msg = scan_message(list[k], "robot0", static_cast<int64_t>(round * list.size() + k));
      lc.publish("OCTOMAP_RT_SCAN_ROBOT0", &msg);
    }
  const int64_t sent = rounds * static_cast<int64_t>(list.size());
  ASSERT_TRUE(wait_until_done(server, sent, std::chrono::seconds(300)));
  const auto st = server.status();
  server.stop();
  const auto stats = server.producer_stats();
  expect_counts_balance(stats);
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].received, sent);
  EXPECT_GT(stats[0].dropped, 0) << "a one-scan budget must overflow when 30 scans arrive at once";
  EXPECT_GT(stats[0].applied, 0);
  EXPECT_EQ(stats[0].missed, 0);  // drops happen after arrival: they are not seq gaps
  const auto order = server.applied_order();
  EXPECT_EQ(static_cast<int64_t>(order.size()), stats[0].applied);
  EXPECT_TRUE(std::is_sorted(order.begin(), order.end(), [](auto& a, auto& b) { return a.seq < b.seq; }));
  EXPECT_NE(st.queue_policy.find("newest scan is dropped"), std::string::npos);
}

// More scan channels than --max-producers: the extra ones share one "*" entry whose scans
// are all rejected (bounded memory whatever the channel names), and are still counted.
TEST(ServerMemq, ProducersBeyondTheLimitAreRejectedAndCounted) {
  auto cfg = test_config(0.1, true);
  cfg.max_producers = 2;
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  for (const char* robot : {"a1", "a2", "a3", "a4"}) {
    const auto msg = small_scan(robot, 0, 10);
    lc.publish(channel_of(robot), &msg);
  }
  ASSERT_TRUE(wait_until_done(server, 4));
  const auto stats = server.producer_stats();
  expect_counts_balance(stats);
  ASSERT_EQ(stats.size(), 3u);
  const auto* other = producer_on(stats, "*");
  ASSERT_NE(other, nullptr);
  EXPECT_EQ(other->received, 2);
  EXPECT_EQ(reason_count(*other, Reject::kTooManyProducers), 2);
  EXPECT_EQ(producer_on(stats, "OCTOMAP_RT_SCAN_A1")->applied, 1);
  EXPECT_EQ(producer_on(stats, "OCTOMAP_RT_SCAN_A2")->applied, 1);
  server.stop();
}

// stop() right after the scans arrived: intake closes, and every queued scan is still
// applied (drained), not lost.
TEST(ServerMemq, StopDrainsQueuedScans) {
  const auto scans = robot_scans(1, 6, 4);
  lcm::LCM lc("memq://");
  const auto cfg = test_config(0.1, true);
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  server.start();
  const auto& list = scans.at("robot0");
  for (size_t k = 0; k < list.size(); ++k) {
    const auto msg = scan_message(list[k], "robot0", static_cast<int64_t>(k));
    lc.publish("OCTOMAP_RT_SCAN_ROBOT0", &msg);
  }
  int64_t received = 0, in_flight = 0;
  for (int i = 0; i < 2000 && received < 6; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    const auto st = server.producer_stats();
    received = st.empty() ? 0 : st[0].received;
    in_flight = st.empty() ? 0 : st[0].in_flight;
  }
  ASSERT_EQ(received, 6);
  EXPECT_GT(in_flight, 0) << "stop() should find scans still queued (the test would prove nothing)";
  server.stop();
  const auto st = server.producer_stats();
  expect_counts_balance(st);
  EXPECT_EQ(st[0].applied, 6);
  EXPECT_EQ(server.applied_order().size(), 6u);
  // The status's map numbers are OctoMap's own.
  const auto status = server.status();
  server.with_map([&](const octomap::OcTree& t) {
    EXPECT_EQ(status.num_nodes, static_cast<int64_t>(t.size()));
    EXPECT_EQ(status.num_leaf_nodes, static_cast<int64_t>(t.getNumLeafNodes()));
    EXPECT_NEAR(static_cast<double>(status.memory_bytes), static_cast<double>(t.memoryUsage()), 1024.0);
    return 0;
  });
  EXPECT_EQ(status.scans_applied, 6);
}

}  // namespace
}  // namespace ort::test
