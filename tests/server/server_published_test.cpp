// What the daemon publishes, as an LCM subscriber on the server's memq:// instance sees it
// (memq delivers on the server's LCM thread while it runs).
#include <chrono>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/mapping_server.h"
#include "octomap_rt/map_delta_t.hpp"
#include "octomap_rt/server_status_t.hpp"
#include "protocol/channels.h"
#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

// Every message of one type delivered on a subscribed channel; the handler runs on the
// server's LCM thread, so readers take the lock.
template <class Msg>
struct MessageSink {
  std::mutex m;
  std::vector<Msg> got;
  void on(const lcm::ReceiveBuffer*, const std::string&, const Msg* msg) {
    std::lock_guard lock(m);
    got.push_back(*msg);
  }
};

// The first delta that reaches `version`, waiting up to 5 s (sets go out at 10 Hz).
std::optional<octomap_rt::map_delta_t> first_delta_reaching(MessageSink<octomap_rt::map_delta_t>& sink,
                                                            int64_t version) {
  for (int k = 0; k < 500; ++k) {
    {
      std::lock_guard lock(sink.m);
      for (const auto& d : sink.got)
        if (d.to_version >= version) return d;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return std::nullopt;
}

// Status heartbeats reach an LCM subscriber on the status channel.
TEST(ServerMemq, StatusIsPublished) {
  lcm::LCM lc("memq://");
  MessageSink<octomap_rt::server_status_t> sink;  // subscribed before the server's thread handles
  lc.subscribe(ort::protocol::kStatusChannel, &MessageSink<octomap_rt::server_status_t>::on, &sink);
  auto cfg = test_config(0.1, true);
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  server.start();
  const auto msg = small_scan("alpha", 0, 50);
  lc.publish("OCTOMAP_RT_SCAN_ALPHA", &msg);
  ASSERT_TRUE(wait_until_done(server, 1));
  std::this_thread::sleep_for(std::chrono::milliseconds(700));  // a few 0.2 s heartbeats
  server.stop();
  std::lock_guard lock(sink.m);
  ASSERT_GE(sink.got.size(), 2u);
  const auto& last = sink.got.back();
  EXPECT_EQ(last.server_id, "test-server");
  EXPECT_EQ(last.backend, "cpu");
  // (memq delivers only while the server's LCM thread runs, so the heartbeats sent while
  // stopping are not seen here; over udpm they are.)
  EXPECT_EQ(last.scans_applied, 1);
  ASSERT_EQ(last.num_robots, 1);
  EXPECT_EQ(last.robots[0].robot_id, "ALPHA");
  EXPECT_EQ(last.robots[0].scans_applied, 1);
  EXPECT_GT(last.num_nodes, 0);
  EXPECT_DOUBLE_EQ(last.resolution, 0.1);
  bool running_seen = false;
  for (size_t i = 0; i < sink.got.size(); ++i) {
    running_seen |= sink.got[i].state == octomap_rt::server_status_t::STATE_RUNNING;
    if (i > 0) {
      EXPECT_EQ(sink.got[i].seq, sink.got[i - 1].seq + 1);
    }
  }
  EXPECT_TRUE(running_seen);
}

// A scan that changes no voxel's class (the same scan again) still moves the mirrors' version:
// the server sends an empty change set up to its version. Before, nothing was sent, and a
// mirror stayed at the older version (a client waiting for its scan's version waited for good).
TEST(ServerMemq, AScanThatChangesNoClassStillAdvancesTheDeltaVersion) {
  lcm::LCM lc("memq://");
  MessageSink<octomap_rt::map_delta_t> sink;
  lc.subscribe(ort::protocol::kMapDeltaChannel, &MessageSink<octomap_rt::map_delta_t>::on, &sink);
  auto cfg = test_config(0.1, true);
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  server.start();
  const auto first = small_scan("alpha", 0, 50);
  lc.publish("OCTOMAP_RT_SCAN_ALPHA", &first);
  ASSERT_TRUE(wait_until_done(server, 1));
  const auto d1 = first_delta_reaching(sink, 1);
  ASSERT_TRUE(d1) << log.str();
  EXPECT_GT(d1->num_voxels, 0);
  const auto again = small_scan("alpha", 1, 50);  // the same rays: free stays free, occupied occupied
  lc.publish("OCTOMAP_RT_SCAN_ALPHA", &again);
  ASSERT_TRUE(wait_until_done(server, 2));
  const auto d2 = first_delta_reaching(sink, 2);
  server.stop();
  ASSERT_TRUE(d2) << "no change set reached version 2";
  EXPECT_EQ(d2->from_version, 1);
  EXPECT_EQ(d2->to_version, 2);
  EXPECT_EQ(d2->num_voxels, 0);
  EXPECT_EQ(d2->delta_seq, d1->delta_seq + 1);
}

}  // namespace
}  // namespace ort::test
