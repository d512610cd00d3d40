// Persistence of octomap-rt-server's map across stops, restarts and crashes:
//  - SIGTERM saves; a restart loads the map and later scans extend it (the result equals
//    OctoMap fed every scan of both runs in the recorded order); another resolution is refused;
//  - kill -9 while a save is being written, several times: the map file left behind always
//    loads, and the next daemon starts from it.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <thread>

#include "core/clock.h"
#include "daemon/map/applied_order.h"
#include "integration_harness.h"
#include "scene/scan_set.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

bool exists(const std::string& path) {
  struct stat st;
  return ::stat(path.c_str(), &st) == 0;
}

struct Fixture {
  NetworkNamespace ns;
  std::string dir, url;
  std::unique_ptr<StatusWatcher> status;
  explicit Fixture(const std::string& tag) : ns(tag) {
    if (!ns.ok()) return;
    dir = make_test_dir(tag);
    url = test_lcm_url(2, ns.rmem_max());
    status = std::make_unique<StatusWatcher>(url);
  }
  std::unique_ptr<ChildProcess> start_server(const std::vector<std::string>& extra, const std::string& log_name) {
    std::vector<std::string> argv{server_program(), "--lcm-url", url};
    argv.insert(argv.end(), extra.begin(), extra.end());
    status->clear();
    return std::make_unique<ChildProcess>(argv, dir + "/" + log_name);
  }
  std::unique_ptr<ChildProcess> replay(const std::string& graph, const std::string& robot,
                                       const std::vector<std::string>& extra, const std::string& log_name) {
    std::vector<std::string> argv{client_program(), "replay", graph, "--robot", robot, "--lcm-url", url, "-q"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return std::make_unique<ChildProcess>(argv, dir + "/" + log_name);
  }
  // Waits for a status (from the current daemon: this pid) satisfying pred.
  bool wait_status(pid_t pid, const std::function<bool(const octomap_rt::server_status_t&)>& pred, double s) {
    return status->wait_for([&](const auto& st) { return st.pid == pid && pred(st); }, s).has_value();
  }
};

TEST(ServerPersistenceIntegration, SigtermSavesAndARestartExtendsTheMap) {
  const std::string graph = data_file("3dtk_dat/3dtk_3scans.graph");
  if (graph.empty()) return;
  const ScanSet scans = load_scan_graph(graph);
  Fixture f("persist");
  ASSERT_TRUE(f.ns.ok()) << f.ns.error();
  const std::string map = f.dir + "/map.ot";
  const std::vector<std::string> flags{"-r", "0.2", "--map", map, "--save-interval", "0"};

  // Run 1: scan 0 from robot alpha, then SIGTERM.
  auto server = f.start_server(flags, "server1.log");
  ASSERT_TRUE(f.wait_status(
      server->pid(), [](const auto&) { return true; }, 60))
      << server->log();
  auto alpha = f.replay(graph, "alpha", {"--first", "0", "--count", "1"}, "alpha.log");
  EXPECT_EQ(alpha->wait(60), 0) << alpha->log();
  ASSERT_TRUE(f.wait_status(
      server->pid(), [](const auto& s) { return total_applied(s) == 1; }, 120))
      << server->log();
  server->signal(SIGTERM);
  ASSERT_EQ(server->wait(120), 0) << server->log();
  ASSERT_TRUE(exists(map)) << "no map saved at SIGTERM\n" << server->log();
  const auto after_run1 = load_ot(map);
  ASSERT_TRUE(after_run1);
  ScanSet first;
  first.scans.push_back(scans.scans[0]);
  EXPECT_TRUE(compare_leaves(*after_run1, *octomap_reference(first, 0.2, -1.0)).maps_equal());

  // Another resolution is refused, clearly, and leaves the map alone.
  auto wrong = f.start_server({"-r", "0.1", "--map", map}, "server_wrong_res.log");
  const auto wrong_rc = wrong->wait(60);
  ASSERT_TRUE(wrong_rc.has_value()) << "the daemon accepted a 0.2 m map at -r 0.1";
  EXPECT_NE(*wrong_rc, 0);
  EXPECT_NE(wrong->log().find("resolution"), std::string::npos) << wrong->log();
  EXPECT_TRUE(compare_leaves(*load_ot(map), *after_run1).maps_equal());

  // Run 2: loads the map; scans 1 and 2 from robot beta extend it.
  server = f.start_server(flags, "server2.log");
  ASSERT_TRUE(f.wait_status(
      server->pid(), [](const auto&) { return true; }, 60))
      << server->log();
  auto beta = f.replay(graph, "beta", {"--first", "1", "--count", "2"}, "beta.log");
  EXPECT_EQ(beta->wait(60), 0) << beta->log();
  ASSERT_TRUE(f.wait_status(
      server->pid(), [](const auto& s) { return total_applied(s) == 2; }, 120))
      << server->log();
  server->signal(SIGTERM);
  ASSERT_EQ(server->wait(120), 0) << server->log();

  const daemon::AppliedOrderFile order = daemon::read_applied_order(map + ".order");
  ASSERT_EQ(order.entries.size(), 3u);
  ScanSet all;
  for (const auto& e : order.entries) {
    const bool is_alpha = same_robot(e.robot_id, "alpha");
    all.scans.push_back(scans.scans[is_alpha ? 0 : 1 + e.seq]);
  }
  const auto after_run2 = load_ot(map);
  ASSERT_TRUE(after_run2);
  const TreeDiff d = compare_leaves(*after_run2, *octomap_reference(all, 0.2, -1.0));
  EXPECT_EQ(d.differing_voxels, 0u) << d.first_difference;
  EXPECT_EQ(d.differing_logodds, 0u) << d.first_difference;
  EXPECT_GT(d.leaves_a, compare_leaves(*after_run1, *after_run1).leaves_a) << "run 2 did not extend the map";
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(f.dir);
}

TEST(ServerPersistenceIntegration, KillNineDuringSavesAlwaysLeavesALoadableMap) {
  const std::string graph = data_file("3dtk_dat/3dtk_3scans.graph");
  if (graph.empty()) return;
  Fixture f("kill9");
  ASSERT_TRUE(f.ns.ok()) << f.ns.error();
  const std::string map = f.dir + "/map.ot";
  const std::string tmp = map + ".tmp";
  // A finer map saves for longer, and a save after every change: most moments are inside one.
  const std::vector<std::string> flags{"-r", "0.1", "--map", map, "--save-interval", "0.05"};
  std::mt19937 rng(7);

  constexpr int kRounds = 6;
  int killed_mid_save = 0;
  double previous_volume = 0;
  for (int round = 0; round < kRounds; ++round) {
    auto server = f.start_server(flags, "server" + std::to_string(round) + ".log");
    ASSERT_TRUE(f.wait_status(
        server->pid(), [](const auto&) { return true; }, 60))
        << "round " << round << ": the daemon did not start from the map left by the kill\n"
        << server->log();
    auto robot = f.replay(graph, "r" + std::to_string(round), {"--repeat", "100", "--rate", "5"},
                          "robot" + std::to_string(round) + ".log");
    // Let it apply and save at least once.
    ASSERT_TRUE(f.wait_status(
        server->pid(), [](const auto& s) { return s.map_saves >= 1; }, 120))
        << server->log();
    // Most rounds: kill the moment a save's temporary file appears (a save in progress);
    // the others at a random moment.
    bool mid_save = false;
    if (round % 3 != 2) {
      const auto deadline = SteadyClock::now() + std::chrono::seconds(20);
      while (!exists(tmp) && SteadyClock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
      mid_save = exists(tmp);
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(std::uniform_int_distribution<int>(100, 1500)(rng)));
    }
    server->signal(SIGKILL);
    ASSERT_TRUE(server->wait(30).has_value());
    robot->signal(SIGKILL);
    robot->wait(30);
    if (mid_save && exists(tmp)) ++killed_mid_save;

    ASSERT_TRUE(exists(map)) << "round " << round << ": no map file after kill -9";
    const auto tree = load_ot(map);
    ASSERT_TRUE(tree) << "round " << round << ": the map file left by kill -9 does not load";
    EXPECT_DOUBLE_EQ(tree->getResolution(), 0.1);
    uint64_t leaves = 0;
    double volume = 0;  // known space [m^3]: a voxel once observed stays known, pruned or not
    for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) {
      ++leaves;
      volume += std::pow(it.getSize(), 3);
    }
    std::printf("round %d: killed %s; map has %llu stored leaves, %.1f m^3 known; %s\n", round,
                mid_save ? "while a save was being written" : "at a random moment", (unsigned long long)leaves, volume,
                exists(tmp) ? "an interrupted .tmp lies beside it" : "no .tmp beside it");
    // Each round starts from the map the previous kill left and only adds observations.
    EXPECT_GE(volume, previous_volume * (1 - 1e-9)) << "round " << round << ": the map lost known space";
    previous_volume = volume;
  }
  std::printf("%d of %d kills hit a save in progress\n", killed_mid_save, kRounds);
  EXPECT_GE(killed_mid_save, 2) << "too few kills landed inside a save to show anything";
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(f.dir);
}

}  // namespace
}  // namespace ort::test
