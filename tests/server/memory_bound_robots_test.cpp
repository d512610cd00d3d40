// Two robots under the memory bound (--max-map-memory, daemon/map/map_residency.h), as users
// run them: two producers over memq://, each mapping its own half of the real 3DTK scans (cut
// into wedges about their sensor), their scans in the queue together, twice round, under a
// bound half their map, so regions must go and come back. The map with eviction (the tree
// and the store: whole_map) is OctoMap's map of the same scans in the order the server applied
// them, voxel for voxel and log-odds for log-odds, whichever regions the working set keeps in
// memory: T from the robots' scan rate (the default), a T that keeps every region touched in
// the run in use (only the overshoot rule evicts), and one that keeps none (plain least
// recently touched).
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "daemon/map/applied_order.h"
#include "scene/scan_set.h"
#include "server/memq_producers.h"
#include "server/scan_fixtures.h"
#include "support/octomap_reference.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

constexpr size_t kThin = 6;     // every 6th point: OctoMap's reference maps stay quick
constexpr size_t kWedges = 12;  // per scan, by azimuth in the sensor's frame

// Robot -> its scans: "alpha" the wedges of one half of each scan's azimuths, "beta" the other.
std::map<std::string, std::vector<PosedScan>> robots_scans() {
  const ScanSet all = load_scan_graph(data_file("3dtk_dat/3dtk_3scans.graph"));
  std::map<std::string, std::vector<PosedScan>> robots;
  for (const PosedScan& s : all.scans) {
    std::vector<PosedScan> wedges(kWedges, PosedScan{s.pose, {}});
    for (size_t i = 0; i < s.points.size(); i += kThin) {
      const octomap::point3d& p = s.points[i];
      const double a = std::atan2(p.y(), p.x()) + M_PI;
      wedges[std::min(kWedges - 1, size_t(a / (2 * M_PI) * kWedges))].points.push_back(p);
    }
    for (size_t w = 0; w < kWedges; ++w)
      if (wedges[w].points.size() > 0) robots[w < kWedges / 2 ? "alpha" : "beta"].push_back(wedges[w]);
  }
  return robots;
}

struct BoundCounts {
  uint64_t evictions = 0, restores = 0;
};

// The two robots' scans, twice round (a robot's scan k + n is its scan k again), a scan of
// each in the queue at once, under `bound` with the working set's T `working_set_s`.
BoundCounts run_two_robots(const std::map<std::string, std::vector<PosedScan>>& robots, uint64_t bound,
                           double working_set_s, const std::string& tag) {
  const std::string dir = temp_dir("memory-bound-robots-" + tag);
  auto cfg = test_config(0.1, true);
  cfg.map_path = dir + "/map.ot";
  cfg.max_map_memory = bound;
  cfg.working_set_s = working_set_s;
  // Both robots' scans must be applied (the test compares maps, not the overload rules): the
  // shared class's budget refuses a robot id without history's scan predicted slow while
  // another streams (daemon/intake/shared_class_budget.h), which a loaded machine makes likely.
  cfg.scan_costs.shared.enabled = false;
  MemqServer fixture(cfg);
  auto& [lc, log, server] = fixture;
  const size_t rounds = 2 * std::max(robots.at("alpha").size(), robots.at("beta").size());
  int64_t sent = 0;
  for (size_t k = 0; k < rounds; ++k) {
    for (const auto& [robot, scans] : robots) {
      const auto msg = scan_message(scans[k % scans.size()], robot, static_cast<int64_t>(k));
      lc.publish(channel_of(robot), &msg);
      ++sent;
    }
    if (!wait_until_done(server, sent)) {
      ADD_FAILURE() << tag << ": the scans of round " << k << " were not all handled:\n" << log.str();
      return {};
    }
  }
  const auto stats = server.producer_stats();
  expect_counts_balance(stats);
  for (const auto& p : stats) EXPECT_EQ(p.applied, p.received) << tag << " " << p.channel << ":\n" << log.str();

  // OctoMap's map of the scans in the applied order.
  ScanSet ordered;
  for (const daemon::AppliedEntry& e : server.applied_order()) {
    const auto& scans = robots.at(e.robot_id);
    ordered.scans.push_back(scans[static_cast<size_t>(e.seq) % scans.size()]);
  }
  EXPECT_EQ(ordered.scans.size(), size_t(sent)) << tag;
  const auto reference = octomap_reference(ordered, cfg.engine.resolution, cfg.engine.max_range);
  const auto whole = server.whole_map();
  const TreeDiff d = compare_leaves(*whole, *reference);
  EXPECT_TRUE(d.maps_equal()) << tag << ": " << d.differing_voxels << " voxels, " << d.differing_logodds
                              << " log-odds differ: " << d.first_difference;
  EXPECT_GT(d.leaves_b, 10000u) << tag;
  EXPECT_EQ(compare_structure(*whole, *reference), "") << tag;
  const daemon::MapResidencyStats st = server.residency_stats();
  server.stop();
  return BoundCounts{st.evictions, st.restores};
}

TEST(MemoryBoundRobots, TwoRobotsMapUnderTheBoundIsOctomapsMapWhateverTheWorkingSet) {
  const auto robots = robots_scans();
  ASSERT_GE(robots.at("alpha").size(), 6u);
  ASSERT_GE(robots.at("beta").size(), 6u);
  ScanSet once;
  for (const auto& [robot, scans] : robots) once.scans.insert(once.scans.end(), scans.begin(), scans.end());
  const uint64_t whole = octomap_reference(once, 0.1, test_config(0.1, true).engine.max_range)->memoryUsage();
  const uint64_t bound = std::max<uint64_t>(whole / 2, 1u << 20);
  ASSERT_GT(whole, bound + bound / 2) << "the map must not fit the bound, even with the overshoot";
  const struct {
    double working_set_s;
    const char* tag;
  } cases[] = {{0, "rate"}, {3600, "all-in-use"}, {0.001, "none-in-use"}};
  for (const auto& c : cases) {
    const BoundCounts r = run_two_robots(robots, bound, c.working_set_s, c.tag);
    EXPECT_GT(r.evictions, 0u) << c.tag;
    EXPECT_GT(r.restores, 0u) << c.tag << ": the second round brought evicted regions back";
  }
}

}  // namespace
}  // namespace ort::test
