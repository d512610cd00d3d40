// lcm-logger records two robots streaming into a daemon; the log then replays into fresh
// daemons, through `octomap-rt replay LOG` (as recorded, and renamed to one robot) and
// through Debian's lcm-logplayer, and each builds the map OctoMap builds from the same scans
// in the order that daemon applied.
#include <gtest/gtest.h>

#include <signal.h>

#include <filesystem>

#include "cli/replay/lcm_log_scans.h"
#include "cli/replay/scan_selection.h"
#include "daemon/map/applied_order.h"
#include "integration_harness.h"
#include "octomap_rt/scan_t.hpp"
#include "protocol/channels.h"
#include "scene/scan_set.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

constexpr int kProducers = 2;
constexpr double kResolution = 0.2;

struct Session {
  std::string dir, url;
  StatusWatcher* status;
  bool wait_applied(pid_t pid, int64_t n, double s) {
    return status
        ->wait_for([&](const auto& st) { return st.pid == pid && total_applied(st) == n && st.scan_queue_depth == 0; },
                   s)
        .has_value();
  }
};

// The map a daemon saved must equal OctoMap fed the scans in the daemon's recorded order.
void expect_map_of_applied_order(const std::string& map, const ScanSet& scans,
                                 const std::vector<std::vector<size_t>>& shares, size_t expected) {
  const daemon::AppliedOrderFile order = daemon::read_applied_order(map + ".order");
  ASSERT_EQ(order.entries.size(), expected);
  ScanSet in_order;
  for (const auto& e : order.entries) {
    const int p = producer_index(e.robot_id, "prod", kProducers);
    ASSERT_GE(p, 0) << e.robot_id;
    ASSERT_LT(static_cast<size_t>(e.seq), shares[p].size());
    in_order.scans.push_back(scans.scans[shares[p][e.seq]]);
  }
  const auto served = load_ot(map);
  ASSERT_TRUE(served);
  const TreeDiff d = compare_leaves(*served, *octomap_reference(in_order, kResolution, -1.0));
  EXPECT_GT(d.leaves_a, 1000u);
  EXPECT_EQ(d.differing_voxels, 0u) << map << ": " << d.first_difference;
  EXPECT_EQ(d.differing_logodds, 0u) << map << ": " << d.first_difference;
}

TEST(ServerLogReplayIntegration, ALoggedSessionReplaysIntoTheDaemonByReplayAndByLcmLogplayer) {
  const std::string graph = data_file("3dtk_dat/3dtk_3scans.graph");
  if (graph.empty()) return;
  const ScanSet scans = load_scan_graph(graph);
  NetworkNamespace ns("logreplay");
  ASSERT_TRUE(ns.ok()) << ns.error();
  StatusWatcher watcher(test_lcm_url(3, ns.rmem_max()));
  ASSERT_TRUE(watcher.good());
  Session run{make_test_dir("logreplay"), test_lcm_url(3, ns.rmem_max()), &watcher};
  const std::string log = run.dir + "/robots.lcmlog";
  auto server_args = [&](const std::string& map) {
    return std::vector<std::string>{server_program(), "-r",    std::to_string(kResolution), "--map", map,
                                    "--lcm-url",      run.url, "--save-interval",           "0"};
  };
  auto started = [&](pid_t pid) {
    return watcher.wait_for([&](const auto& st) { return st.pid == pid; }, 60).has_value();
  };

  // 1. Record: lcm-logger (long option only: 1.3.1's -l is broken) while two robots stream.
  std::vector<std::vector<size_t>> shares;
  size_t expected = 0;
  {
    ChildProcess logger({"lcm-logger", "--lcm-url=" + run.url, "-f", log}, run.dir + "/logger.log");
    ChildProcess server(server_args(run.dir + "/live.ot"), run.dir + "/live_server.log");
    ASSERT_TRUE(started(server.pid())) << server.log();
    std::vector<std::unique_ptr<ChildProcess>> producers;
    for (int i = 0; i < kProducers; ++i) {
      const std::string part = std::to_string(i) + "/" + std::to_string(kProducers);
      producers.push_back(std::make_unique<ChildProcess>(
          std::vector<std::string>{client_program(), "replay", graph, "--robot", "prod" + std::to_string(i), "--part",
                                   part, "--rate", "4", "--lcm-url", run.url},
          run.dir + "/producer" + std::to_string(i) + ".log"));
      cli::ScanSelection sel;
      cli::parse_part(part, sel);
      shares.push_back(cli::select_scans(scans.scans.size(), sel));
      expected += shares.back().size();
    }
    for (auto& p : producers) EXPECT_EQ(p->wait(120), 0) << p->log();
    ASSERT_TRUE(run.wait_applied(server.pid(), expected, 240)) << server.log();
    server.signal(SIGTERM);
    ASSERT_EQ(server.wait(120), 0) << server.log();
    logger.signal(SIGINT);
    ASSERT_TRUE(logger.wait(30).has_value()) << logger.log();
  }
  size_t logged_scans = 0;
  cli::for_each_log_scan(log, ort::protocol::kScanChannelPrefix, [&](const cli::LogScanEvent&) {
    ++logged_scans;
    return true;
  });
  ASSERT_EQ(logged_scans, expected) << "lcm-logger did not record every scan";
  expect_map_of_applied_order(run.dir + "/live.ot", scans, shares, expected);

  // 2. `octomap-rt replay LOG`: scans republished as recorded (robots, channels, seq).
  {
    ChildProcess server(server_args(run.dir + "/by_replay.ot"), run.dir + "/replay_server.log");
    ASSERT_TRUE(started(server.pid())) << server.log();
    ChildProcess player({client_program(), "replay", log, "--speed", "2", "--lcm-url", run.url},
                        run.dir + "/replay_log.log");
    EXPECT_EQ(player.wait(120), 0) << player.log();
    ASSERT_TRUE(run.wait_applied(server.pid(), expected, 240)) << server.log();
    const auto st = watcher.latest();
    for (int i = 0; i < kProducers; ++i) {
      const auto* r = find_robot_ci(*st, "prod" + std::to_string(i));
      ASSERT_NE(r, nullptr);
      EXPECT_EQ(r->scans_received, static_cast<int64_t>(shares[i].size()));
      EXPECT_EQ(r->scans_applied, r->scans_received);
      EXPECT_EQ(r->scans_missed, 0);
    }
    server.signal(SIGTERM);
    ASSERT_EQ(server.wait(120), 0) << server.log();
  }
  expect_map_of_applied_order(run.dir + "/by_replay.ot", scans, shares, expected);

  // 3. lcm-logplayer: the whole log as recorded (the old daemon's status messages too, which
  // carry its pid and are told apart by it).
  {
    ChildProcess server(server_args(run.dir + "/by_logplayer.ot"), run.dir + "/logplayer_server.log");
    ASSERT_TRUE(started(server.pid())) << server.log();
    ChildProcess player({"lcm-logplayer", "--lcm-url=" + run.url, "--speed=2", log}, run.dir + "/logplayer.log");
    EXPECT_EQ(player.wait(120), 0) << player.log();
    ASSERT_TRUE(run.wait_applied(server.pid(), expected, 240)) << server.log();
    server.signal(SIGTERM);
    ASSERT_EQ(server.wait(120), 0) << server.log();
  }
  expect_map_of_applied_order(run.dir + "/by_logplayer.ot", scans, shares, expected);

  // 4. `octomap-rt replay LOG --robot solo`: every logged scan renamed to one robot and
  // renumbered, in log order; the map is OctoMap's of the scans in that order.
  ScanSet log_order;
  cli::for_each_log_scan(log, ort::protocol::kScanChannelPrefix, [&](const cli::LogScanEvent& e) {
    octomap_rt::scan_t m;
    EXPECT_GE(m.decode(e.data, 0, static_cast<int>(e.size)), 0);
    const int p = producer_index(m.robot_id, "prod", kProducers);
    EXPECT_GE(p, 0);
    if (p >= 0) log_order.scans.push_back(scans.scans[shares[p][m.seq]]);
    return true;
  });
  {
    const std::string map = run.dir + "/renamed.ot";
    ChildProcess server(server_args(map), run.dir + "/renamed_server.log");
    ASSERT_TRUE(started(server.pid())) << server.log();
    ChildProcess player({client_program(), "replay", log, "--robot", "solo", "--rate", "4", "--lcm-url", run.url},
                        run.dir + "/renamed.log");
    EXPECT_EQ(player.wait(120), 0) << player.log();
    ASSERT_TRUE(run.wait_applied(server.pid(), expected, 240)) << server.log();
    const auto st = watcher.latest();
    const auto* r = find_robot_ci(*st, "solo");
    ASSERT_NE(r, nullptr);
    EXPECT_EQ(r->scans_applied, static_cast<int64_t>(expected));
    EXPECT_EQ(r->last_seq, static_cast<int64_t>(expected) - 1);
    EXPECT_EQ(r->scans_missed, 0);
    server.signal(SIGTERM);
    ASSERT_EQ(server.wait(120), 0) << server.log();
    const auto served = load_ot(map);
    ASSERT_TRUE(served);
    const TreeDiff d = compare_leaves(*served, *octomap_reference(log_order, kResolution, -1.0));
    EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels, " << d.differing_logodds << " log-odds differ";
  }

  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(run.dir);
}

}  // namespace
}  // namespace ort::test
