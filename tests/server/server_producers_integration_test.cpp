// The daemon with three concurrent producers, real 3D laser scans split among them:
// the map it saves equals `octomap-rt build` (and OctoMap itself) fed the same scans in the
// order the daemon says it applied them, and every producer's scans are accounted for.
#include <gtest/gtest.h>

#include <signal.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>

#include "cli/replay/scan_selection.h"
#include "daemon/map/applied_order.h"
#include "daemon/persistence/map_identity_file.h"
#include "integration_harness.h"
#include "scene/scan_set.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

constexpr int kProducers = 3;
constexpr size_t kRepeat = 3;  // each producer sends its share of the 3 scans 3 times
constexpr double kResolution = 0.2;

TEST(ServerProducersIntegration, ThreeProducersSplitRealScansGiveTheMapOfTheAppliedOrder) {
  const std::string graph = data_file("3dtk_dat/3dtk_3scans.graph");
  if (graph.empty()) return;
  const ScanSet scans = load_scan_graph(graph);
  ASSERT_EQ(scans.scans.size(), 3u);

  NetworkNamespace ns("producers");
  ASSERT_TRUE(ns.ok()) << ns.error();
  const std::string dir = make_test_dir("producers");
  const std::string url = test_lcm_url(1, ns.rmem_max());
  std::printf("namespace: %s, rmem_max %lld, url %s, dir %s\n", ns.how().c_str(), (long long)ns.rmem_max(), url.c_str(),
              dir.c_str());
  StatusWatcher status(url);
  ASSERT_TRUE(status.good());

  const std::string map_path = dir + "/map.ot";
  ChildProcess server({server_program(), "-r", std::to_string(kResolution), "--map", map_path, "--lcm-url", url,
                       "--save-interval", "0"},
                      dir + "/server.log");
  ASSERT_TRUE(status.wait_for([](const auto&) { return true; }, 60)) << "no status from the daemon\n" << server.log();

  // Three robots at once, each with every third scan of the set (--part i/3).
  std::vector<std::unique_ptr<ChildProcess>> producers;
  std::vector<std::vector<size_t>> shares;
  for (int i = 0; i < kProducers; ++i) {
    const std::string part = std::to_string(i) + "/" + std::to_string(kProducers);
    producers.push_back(std::make_unique<ChildProcess>(
        std::vector<std::string>{client_program(), "replay", graph, "--robot", "prod" + std::to_string(i), "--part",
                                 part, "--repeat", std::to_string(kRepeat), "--rate", "4", "--lcm-url", url},
        dir + "/producer" + std::to_string(i) + ".log"));
    cli::ScanSelection sel;
    ASSERT_EQ(cli::parse_part(part, sel), "");
    sel.repeat = kRepeat;
    shares.push_back(cli::select_scans(scans.scans.size(), sel));
  }
  size_t expected_total = 0;
  for (int i = 0; i < kProducers; ++i) {
    EXPECT_EQ(producers[i]->wait(120), 0) << producers[i]->log();
    expected_total += shares[i].size();
  }
  ASSERT_EQ(expected_total, kRepeat * scans.scans.size());

  // Every scan received is applied, rejected or dropped; wait until nothing is in flight.
  const auto done = status.wait_for(
      [&](const octomap_rt::server_status_t& s) {
        return total_applied(s) == static_cast<int64_t>(expected_total) && s.scan_queue_depth == 0 &&
               s.shot_queue_depth == 0;
      },
      240);
  ASSERT_TRUE(done) << "the daemon did not apply " << expected_total << " scans\n" << server.log();
  for (int i = 0; i < kProducers; ++i) {
    const auto* r = find_robot_ci(*done, "prod" + std::to_string(i));
    ASSERT_NE(r, nullptr) << "producer " << i << " missing from the status";
    EXPECT_EQ(r->scans_received, static_cast<int64_t>(shares[i].size()));
    EXPECT_EQ(r->scans_received, r->scans_applied + r->scans_rejected + r->scans_dropped);
    EXPECT_EQ(r->scans_applied, static_cast<int64_t>(shares[i].size()));
    EXPECT_EQ(r->scans_rejected, 0);
    EXPECT_EQ(r->scans_dropped, 0);
    EXPECT_EQ(r->scans_missed, 0);
  }

  server.signal(SIGTERM);  // -> applies what is queued, saves map.ot and map.ot.order
  ASSERT_EQ(server.wait(120), 0) << server.log();

  // The daemon's record of what it applied, mapped back to scans of the set.
  const daemon::AppliedOrderFile order = daemon::read_applied_order(map_path + ".order");
  ASSERT_EQ(order.entries.size(), expected_total);
  // The order file only grows; the map it belongs to is named by the identity beside it: the
  // saved map's size and the number of order lines that belong to it.
  const std::optional<daemon::MapIdentityRecord> identity = daemon::read_map_identity(map_path);
  ASSERT_TRUE(identity.has_value());
  EXPECT_EQ(identity->map_bytes, std::filesystem::file_size(map_path));
  EXPECT_EQ(identity->order_entries, expected_total);
  EXPECT_TRUE(identity->clean);
  ScanSet in_order;
  in_order.name = "3dtk in the daemon's applied order";
  std::map<std::string, int64_t> next_seq;
  bool interleaved = false;
  for (size_t k = 0; k < order.entries.size(); ++k) {
    const daemon::AppliedEntry& e = order.entries[k];
    const int producer = producer_index(e.robot_id, "prod", kProducers);
    ASSERT_GE(producer, 0) << "unknown robot " << e.robot_id;
    ASSERT_GE(e.seq, 0);
    ASSERT_LT(static_cast<size_t>(e.seq), shares[producer].size());
    // One producer's scans are applied in its own publishing order.
    EXPECT_EQ(e.seq, next_seq[e.robot_id]++) << "entry " << k;
    if (k > 0 && order.entries[k - 1].robot_id != e.robot_id) interleaved = true;
    in_order.scans.push_back(scans.scans[shares[producer][e.seq]]);
  }
  EXPECT_TRUE(interleaved) << "the producers' scans were not interleaved: not a concurrency test";

  // Reference 1: `octomap-rt build` of the same scans in that order.
  const std::string ordered_graph = dir + "/applied_order.graph";
  save_scan_graph(in_order, ordered_graph);
  ChildProcess build(
      {client_program(), "build", ordered_graph, "-r", std::to_string(kResolution), "-o", dir + "/build.ot", "-q"},
      dir + "/build.log");
  ASSERT_EQ(build.wait(240), 0) << build.log();

  const auto served = load_ot(map_path);
  const auto built = load_ot(dir + "/build.ot");
  ASSERT_TRUE(served && built);
  const TreeDiff d = compare_leaves(*served, *built);
  std::printf("daemon map: %llu leaves; build: %llu leaves; differing voxels %llu, log-odds %llu\n",
              (unsigned long long)d.leaves_a, (unsigned long long)d.leaves_b, (unsigned long long)d.differing_voxels,
              (unsigned long long)d.differing_logodds);
  EXPECT_GT(d.leaves_a, 1000u);
  EXPECT_EQ(d.differing_voxels, 0u) << d.first_difference;
  EXPECT_EQ(d.differing_logodds, 0u) << d.first_difference;

  // Reference 2: OctoMap itself, same order.
  const auto octomap = octomap_reference(in_order, kResolution, -1.0);
  const TreeDiff o = compare_leaves(*served, *octomap);
  EXPECT_TRUE(o.maps_equal()) << o.differing_voxels << " voxels, " << o.differing_logodds
                              << " log-odds differ from OctoMap: " << o.first_difference;

  // For contrast (not asserted): how much the order matters with these scans. Clamping
  // makes log-odds order-dependent, so a wrong order record would show up as differences.
  ScanSet grouped;
  for (const auto& share : shares)
    for (size_t idx : share) grouped.scans.push_back(scans.scans[idx]);
  const TreeDiff g = compare_leaves(*served, *octomap_reference(grouped, kResolution, -1.0));
  std::printf("for contrast: the same scans grouped by producer give %llu differing log-odds\n",
              (unsigned long long)g.differing_logodds);

  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

// Producers may also send points already in the map frame (--points-frame map: OctoMap's
// Pointcloud::transform done by the producer); the map is the same as from sensor-frame
// scans with poses, which the daemon transforms itself.
TEST(ServerProducersIntegration, MapFramePointsGiveTheSameMapAsSensorFramePoints) {
  const std::string graph = data_file("3dtk_dat/3dtk_3scans.graph");
  if (graph.empty()) return;
  const ScanSet scans = load_scan_graph(graph);
  NetworkNamespace ns("mapframe");
  ASSERT_TRUE(ns.ok()) << ns.error();
  const std::string dir = make_test_dir("mapframe");
  const std::string url = test_lcm_url(4, ns.rmem_max());
  StatusWatcher status(url);
  ASSERT_TRUE(status.good());
  const std::string map_path = dir + "/map.ot";
  ChildProcess server({server_program(), "-r", std::to_string(kResolution), "--map", map_path, "--lcm-url", url,
                       "--save-interval", "0"},
                      dir + "/server.log");
  ASSERT_TRUE(status.wait_for([](const auto&) { return true; }, 60)) << server.log();
  ChildProcess robot({client_program(), "replay", graph, "--robot", "mapper", "--points-frame", "map", "--rate", "4",
                      "--lcm-url", url, "-q"},
                     dir + "/robot.log");
  EXPECT_EQ(robot.wait(120), 0) << robot.log();
  ASSERT_TRUE(status.wait_for([&](const auto& s) { return total_applied(s) == 3 && s.scan_queue_depth == 0; }, 240))
      << server.log();
  server.signal(SIGTERM);
  ASSERT_EQ(server.wait(120), 0) << server.log();
  const auto served = load_ot(map_path);
  ASSERT_TRUE(served);
  const TreeDiff d = compare_leaves(*served, *octomap_reference(scans, kResolution, -1.0));
  EXPECT_GT(d.leaves_a, 1000u);
  EXPECT_EQ(d.differing_voxels, 0u) << d.first_difference;
  EXPECT_EQ(d.differing_logodds, 0u) << d.first_difference;
  if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ort::test
