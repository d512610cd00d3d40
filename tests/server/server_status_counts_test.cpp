// The status's map figures on a map big enough that its leaves are not counted at every
// status (daemon/mapping_server_status.cpp: the count walks the whole tree under the map lock),
// the run summary's slowest scans as the pipeline records them, and the LCM thread's handler
// errors as the status and the log report them.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

#include "daemon/mapping_server.h"
#include "octomap_rt/map_edit_ack_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "protocol/channels.h"
#include "scene/scan_set.h"
#include "server/query_test_support.h"
#include "server/scan_fixtures.h"
#include "support/test_data.h"

namespace ort::test {
namespace {

// A big map's leaves are counted (a walk of the whole tree under the map lock) at most every
// 10 s while scans are applied, and once more when the pipeline has drained: the status after
// stop() still has OctoMap's own figures, though statuses were taken while the map grew.
TEST(ServerStatusCounts, BigMapIsExactOnceDrained) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  if (path.empty()) return;
  const ScanSet set = load_scan_graph(path);
  auto cfg = test_config(0.1, true);
  cfg.status.period_s = 0.02;
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  for (size_t k = 0; k < set.scans.size(); ++k) {
    const auto msg = scan_message(set.scans[k], "husky1", static_cast<int64_t>(k));
    lc.publish(std::string(ort::protocol::kScanChannelPrefix) + "HUSKY1", &msg);
    ASSERT_TRUE(wait_until_done(server, static_cast<int64_t>(k + 1)));
    (void)server.status();  // a status while the map grows
  }
  server.stop();
  const auto status = server.status();
  server.with_map([&](const octomap::OcTree& t) {
    EXPECT_GT(t.size(), 65'536u) << "a map big enough for the throttled count";
    EXPECT_EQ(status.num_nodes, static_cast<int64_t>(t.size()));
    EXPECT_EQ(status.num_leaf_nodes, static_cast<int64_t>(t.getNumLeafNodes()));
    EXPECT_NEAR(static_cast<double>(status.memory_bytes), static_cast<double>(t.memoryUsage()), 1024.0);
    return 0;
  });
}

// The status' leaf count is OctoMap's getNumLeafNodes() of the map at every status while a big
// map grows (the octree stage's running count, with and without the read replica: no walk of
// the tree, which made the count lag up to 10 s behind), after a reset and at every status of
// scans from the empty tree again; after clear-boxes and decay slices (changes that do not say
// how they changed the leaves) once the status counted them again (within a second).
TEST(ServerStatusCounts, LeafCountIsOctomapsAfterScansEditsResetsAndDecay) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  if (path.empty()) return;
  const ScanSet set = load_scan_graph(path);
  for (const bool replica : {false, true}) {
    SCOPED_TRACE(replica ? "with the read replica" : "without the read replica");
    lcm::LCM lc("memq://");
    auto cfg = test_config(0.1, true);
    cfg.read_replica = replica;
    cfg.queries.control_token = kToken;
    cfg.status.period_s = 0.02;
    cfg.upkeep.decay_half_life_s = 10;
    cfg.upkeep.decay_step_s = 5;
    cfg.upkeep.manual = true;
    cfg.upkeep.slice_nodes = 20'000;
    std::ostringstream log;
    daemon::MappingServer server(cfg, lc, log);
    Replies replies(server);
    server.start();
    int64_t seq = 0;
    // After a change that forgets the count, the status counts it again by a walk, spaced to
    // at most 1/20 of the time: within a second here (the replica, if any, caught up first).
    auto expect_exact = [&](const std::string& after) {
      (void)server.with_readable_map([](const octomap::OcTree&) { return 0; });
      const auto leaves = server.with_map([](const octomap::OcTree& t) { return t.getNumLeafNodes(); });
      int64_t counted = -1;
      for (int i = 0; i < 100 && counted != static_cast<int64_t>(leaves); ++i) {
        if (i > 0) std::this_thread::sleep_for(std::chrono::milliseconds(50));
        counted = server.status().num_leaf_nodes;
      }
      EXPECT_EQ(counted, static_cast<int64_t>(leaves)) << "after " << after;
    };
    // At once (no walk): the map of record's running count.
    auto expect_kept = [&](const std::string& after) {
      const auto status = server.status();
      const auto leaves = server.with_map([](const octomap::OcTree& t) { return t.getNumLeafNodes(); });
      EXPECT_EQ(status.num_leaf_nodes, static_cast<int64_t>(leaves)) << "after " << after;
    };
    auto scan = [&](size_t k) {
      const auto msg = scan_message(set.scans[k], "husky1", seq++);
      lc.publish(std::string(ort::protocol::kScanChannelPrefix) + "HUSKY1", &msg);
      ASSERT_TRUE(wait_until_done(server, seq));
    };
    for (int pass = 0; pass < 2; ++pass)
      for (size_t k = 0; k < set.scans.size(); ++k) {
        scan(k);
        expect_kept("scan " + std::to_string(seq));
      }
    const int64_t nodes = server.with_map([](const octomap::OcTree& t) { return static_cast<int64_t>(t.size()); });
    EXPECT_GT(nodes, 65'536) << "a map big enough that the status never counted its leaves at every status";
    int64_t edit_id = 0;
    auto edit = [&](int8_t op, const std::array<double, 3>& lo, const std::array<double, 3>& hi) {
      octomap_rt::map_edit_t e{};
      e.request_id = ++edit_id, e.client_id = "op", e.reply_channel = kReply, e.op = op;
      std::copy(lo.begin(), lo.end(), e.box_min), std::copy(hi.begin(), hi.end(), e.box_max);
      sign(e);
      lc.publish(ort::protocol::kMapEditChannel, &e);
      ASSERT_EQ(replies.wait_for<octomap_rt::map_edit_ack_t>(edit_id).status, Reply::REPLY_OK);
    };
    edit(octomap_rt::map_edit_t::OP_CLEAR_TO_UNKNOWN, {-2.05, -3.3, -0.4}, {3.3, 2.05, 1.1});
    expect_exact("a clear-box to unknown");
    edit(octomap_rt::map_edit_t::OP_CLEAR_TO_FREE, {4.05, 1.3, -0.4}, {6.3, 3.05, 0.9});
    expect_exact("a clear-box to free");
    server.upkeep()->decay_steps(3);
    expect_exact("decay slices");
    scan(0);
    expect_exact("a scan after the decay");
    edit(octomap_rt::map_edit_t::OP_RESET, {0, 0, 0}, {0, 0, 0});
    expect_kept("a reset");
    scan(1);
    expect_kept("a scan into the empty map");
    scan(2);
    expect_kept("another scan");
    server.stop();
  }
}

// The summary's slowest scans are scans the daemon applied (robot, seq), each with parts that
// add up to its end-to-end time, the voxels it applied, and the first scan's new nodes.
TEST(ServerStatusCounts, SlowestScansAreAppliedScansWithTheirParts) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  if (path.empty()) return;
  const ScanSet set = load_scan_graph(path);
  MemqServer fixture(test_config(0.1, true));
  auto& [lc, log, server] = fixture;
  int64_t sent = 0;
  for (int round = 0; round < 2; ++round)
    for (size_t k = 0; k < set.scans.size(); ++k, ++sent) {
      const std::string robot = sent % 2 ? "husky2" : "husky1";  // odd seqs from husky2
      const auto msg = scan_message(set.scans[k], robot, sent);
      lc.publish(std::string(ort::protocol::kScanChannelPrefix) + (sent % 2 ? "HUSKY2" : "HUSKY1"), &msg);
    }
  ASSERT_TRUE(wait_until_done(server, sent));
  server.stop();
  std::ostringstream summary;
  server.print_summary(summary);
  std::istringstream lines(summary.str());
  std::string line;
  std::set<long long> seqs;
  double previous = 1e300;
  while (std::getline(lines, line)) {
    if (line.rfind("    #", 0) != 0) continue;
    long long index = 0, seq = 0, voxels = 0, new_nodes = 0;
    char robot[32] = {};
    double at = 0, e2e = 0, decode = 0, queue = 0, stage1 = 0, up = 0, prep = 0, shoot = 0, compact = 0, handoff = 0,
           stage2 = 0, lock = 0, octree = 0, deltas = 0;
    ASSERT_EQ(
        std::sscanf(line.c_str(),
                    "    #%lld %31s seq %lld at +%lf s: %lf ms = decode %lf + queue %lf + stage 1 %lf (upload %lf, "
                    "prepare %lf, shoot %lf, compact %lf) + hand-off %lf + stage 2 %lf (lock wait %lf, octree "
                    "%lf, deltas %lf); %lld voxels, %lld new nodes",
                    &index, robot, &seq, &at, &e2e, &decode, &queue, &stage1, &up, &prep, &shoot, &compact, &handoff,
                    &stage2, &lock, &octree, &deltas, &voxels, &new_nodes),
        19)
        << line;
    EXPECT_GE(index, 1);
    EXPECT_LE(index, sent);
    EXPECT_EQ(std::string(robot), seq % 2 ? "husky2" : "husky1") << line;
    EXPECT_TRUE(seqs.insert(seq).second) << "listed twice: " << line;
    EXPECT_LE(e2e, previous) << "slowest first";
    previous = e2e;
    EXPECT_NEAR(decode + queue + stage1 + handoff + stage2, e2e, 0.03) << line;  // 5 figures rounded to 0.005
    EXPECT_LE(lock + octree + deltas, stage2 + 0.02) << line;
    EXPECT_GT(voxels, 0) << line;
    if (index == 1) {
      EXPECT_GT(new_nodes, 0) << "the first scan builds the map: " << line;
    }
    EXPECT_GE(at, 0.0);
  }
  EXPECT_EQ(seqs.size(), std::min<size_t>(5, static_cast<size_t>(sent))) << summary.str();
}

// A handler that throws on the LCM thread is caught by the loop, logged once per message through
// the server's log, counted, and the count reaches every later status and the summary.
TEST(ServerStatusCounts, HandlerErrorsReachTheStatus) {
  auto cfg = test_config(0.1, true);
  cfg.status.period_s = 0.02;
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  EXPECT_EQ(server.status().lcm_handler_errors, 0);
  server.lcm_loop().subscribe("ORT_TEST_BROKEN_HANDLER", [](const lcm::ReceiveBuffer&, const std::string&) {
    throw std::runtime_error("a service's handler failed");
  });
  const uint8_t byte = 0;
  for (int i = 0; i < 3; ++i) lc.publish("ORT_TEST_BROKEN_HANDLER", &byte, 1);
  for (int i = 0; i < 2000 && server.status().lcm_handler_errors < 3; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(server.status().lcm_handler_errors, 3);
  server.stop();
  std::ostringstream summary;
  server.print_summary(summary);
  EXPECT_NE(summary.str().find("LCM handler errors: 3 messages"), std::string::npos) << summary.str();
  const std::string text = log.str();
  size_t lines = 0;
  for (size_t at = text.find("a service's handler failed"); at != std::string::npos;
       at = text.find("a service's handler failed", at + 1))
    ++lines;
  EXPECT_EQ(lines, 3u) << text;
  EXPECT_NE(text.find("error: unexpected error on ORT_TEST_BROKEN_HANDLER: a service's handler failed"),
            std::string::npos)
      << text;
}

}  // namespace
}  // namespace ort::test
