// The status's map figures on a map big enough that its leaves are not counted at every
// status (daemon/mapping_server_status.cpp: the count walks the whole tree under the map lock),
// the run summary's slowest scans as the pipeline records them, and the LCM thread's handler
// errors as the status and the log report them.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <gtest/gtest.h>

#include "daemon/mapping_server.h"
#include "protocol/channels.h"
#include "scene/scan_set.h"
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
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.status_period_s = 0.02;
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  server.start();
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

// The summary's slowest scans are scans the daemon applied (robot, seq), each with parts that
// add up to its end-to-end time, the voxels it applied, and the first scan's new nodes.
TEST(ServerStatusCounts, SlowestScansAreAppliedScansWithTheirParts) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  if (path.empty()) return;
  const ScanSet set = load_scan_graph(path);
  lcm::LCM lc("memq://");
  std::ostringstream log;
  daemon::MappingServer server(test_config(0.1, true), lc, log);
  server.start();
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
  lcm::LCM lc("memq://");
  auto cfg = test_config(0.1, true);
  cfg.status_period_s = 0.02;
  std::ostringstream log;
  daemon::MappingServer server(cfg, lc, log);
  server.start();
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
