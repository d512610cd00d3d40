// The memory bound's edges in the daemon (daemon/map/map_residency.h), as users meet them: the
// map's memory right after a scan's restores, before its update (what a status taken while
// the update runs reports), stays within 10 % of the bound; a .bt --prior larger than the
// bound is loaded within it. Both compared with OctoMap's own map on real data.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "core/sensor_model.h"
#include "daemon/map/map_residency.h"
#include "daemon/map/map_state.h"
#include "octree/octree_update.h"
#include "octree/real_scan_voxels.h"
#include "octree/region.h"
#include "octree/residency/working_set_window.h"
#include "query/key_box.h"
#include "server/scan_fixtures.h"
#include "support/memory_spill.h"
#include "support/test_data.h"
#include "support/tree_compare.h"

namespace ort::test {
namespace {

// The real 3DTK scans cut into wedges around their sensor (each of them sees the whole map; a
// scan that sees more than the bound cannot fit it), every 4th point, shot as the daemon does.
std::vector<VoxelList> wedge_scans() {
  constexpr int kWedges = 24;
  return shoot_real_scans("3dtk_dat/3dtk_3scans.graph", SIZE_MAX,
                          [](const std::vector<octomap::point3d>& world, const octomap::point3d& origin) {
                            std::vector<std::vector<octomap::point3d>> wedges(kWedges);
                            for (size_t i = 0; i < world.size(); i += 4) {
                              const double a = std::atan2(world[i].y() - origin.y(), world[i].x() - origin.x()) + M_PI;
                              wedges[std::min(kWedges - 1, int(a / (2 * M_PI) * kWedges))].push_back(world[i]);
                            }
                            return wedges;
                          });
}

// The working set's clock (octree/residency/working_set_window.h), stepped by the test: which
// regions are in use never depends on how fast the machine runs the scans. One robot at 10 Hz
// by default: T = 5 s, a wedge's regions in use for the next 50 scans.
struct SteppedClock {
  WorkingSetWindow::TimePoint now{};
  void step(std::chrono::milliseconds ms = std::chrono::milliseconds(100)) {
    now += std::chrono::duration_cast<SteadyClock::duration>(ms);
  }
  WorkingSetWindow window() {
    return WorkingSetWindow(0, [this] { return now; });
  }
};

// Stage 2's order (touch, update, enforce) over the wedges twice, under a bound 3/4 of the
// map: the second pass brings regions back before each update.
TEST(MapResidency, RestoresMakeRoomBeforeTheUpdate) {
  const std::vector<VoxelList> lists = wedge_scans();
  ASSERT_GE(lists.size(), 12u);
  octomap::OcTree unbounded(0.1);
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  for (int pass = 0; pass < 2; ++pass)
    for (const VoxelList& l : lists) stage.apply(unbounded, l);
  const uint64_t bound = unbounded.memoryUsage() * 3 / 4;

  daemon::MapState map;
  map.tree = std::make_unique<octomap::OcTree>(0.1);
  MemorySpill spill;
  const RegionGrid grid = region_grid(daemon::evict_region_depth(test_config(0.1, true)));  // the daemon's
  std::ostringstream log;
  daemon::MapResidency residency(map, grid, spill, bound, Log(log));
  SteppedClock clock;
  residency.set_working_set(clock.window());
  uint64_t most_after_restores = 0;
  size_t scans = 0, above = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (const VoxelList& l : lists) {
      std::string error;
      clock.step();
      ASSERT_TRUE(residency.touch_scan(*map.tree, l, error)) << error;
      most_after_restores = std::max<uint64_t>(most_after_restores, map.tree->memoryUsage());
      ++scans;
      above += map.tree->memoryUsage() > bound + bound / 10;
      stage.apply(*map.tree, l);
      residency.enforce(*map.tree);
    }
  }
  const daemon::MapResidencyStats st = residency.stats();
  EXPECT_GT(st.restores, 100u) << "scans brought regions back";
  // A wedge's regions (with their siblings) can weigh more than the room a pass can make
  // without taking them: then it stays above. Without the pass before the update about a
  // tenth of these scans were above 1.1x, up to 1.33x.
  EXPECT_LE(above * 20, scans) << above << " of " << scans << " scans above 1.1x the bound after their restores";
  EXPECT_LE(most_after_restores, bound + bound / 4)
      << "after restores, " << double(most_after_restores) / double(bound) << " of the bound";
  octomap::OcTree whole(*map.tree);
  daemon::MapResidency::fill_copy(whole, grid, residency.spilled_regions());
  const TreeDiff d = compare_leaves(whole, unbounded);
  EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels differ: " << d.first_difference;
}

// Scans that keep mapping the same place (32 wedges, twice, 10 Hz: every region was touched in
// the last 3.2 s, all of them in use by the daemon's rule, T = 5 s) under a bound just below their
// map (1/1.05 of it): the map stays above the bound, within kHotOvershoot of it, and nothing
// is evicted, so nothing comes back (before the rule a pass past the bound took regions in
// use down to kLowWater and the next scans restored them); the map = OctoMap's.
TEST(MapResidency, RegionsInUseStayWithinTheOvershoot) {
  std::vector<VoxelList> lists = wedge_scans();
  ASSERT_GE(lists.size(), 40u);
  lists.resize(32);
  octomap::OcTree unbounded(0.1);
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  for (int pass = 0; pass < 2; ++pass)
    for (const VoxelList& l : lists) stage.apply(unbounded, l);
  const auto bound = static_cast<uint64_t>(double(unbounded.memoryUsage()) / 1.05);

  daemon::MapState map;
  map.tree = std::make_unique<octomap::OcTree>(0.1);
  MemorySpill spill;
  const RegionGrid grid = region_grid(daemon::evict_region_depth(test_config(0.1, true)));
  std::ostringstream log;
  daemon::MapResidency residency(map, grid, spill, bound, Log(log));
  SteppedClock clock;
  residency.set_working_set(clock.window());
  uint64_t most = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (const VoxelList& l : lists) {
      std::string error;
      clock.step();
      ASSERT_TRUE(residency.touch_scan(*map.tree, l, error)) << error;
      stage.apply(*map.tree, l);
      residency.enforce(*map.tree);
      most = std::max<uint64_t>(most, map.tree->memoryUsage());
    }
  }
  const daemon::MapResidencyStats st = residency.stats();
  EXPECT_GT(most, bound) << "the map must pass the bound for the rule to matter";
  EXPECT_LE(double(most), daemon::MapResidency::kHotOvershoot * double(bound))
      << double(most) / double(bound) << " of the bound";
  EXPECT_EQ(st.evictions, 0u) << "regions in use were evicted";
  EXPECT_EQ(st.restores, 0u) << "regions in use went back and forth";
  EXPECT_GT(st.hot_overshoots, 0u) << "the passes above the bound are counted";
  const TreeDiff d = compare_leaves(*map.tree, unbounded);
  EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels differ: " << d.first_difference;
}

// Four robots at about 16 Hz each (a scan every 60 ms of a stepped clock, staggered), each
// going round its own quarter of the wedges: a robot is back at a wedge after 18 of its scans,
// 1.08 s and 72 changes of the map later. The working set's T follows the rate (50 x 60 ms =
// 3 s), so every region is in use all along: under a bound just below the map (1/1.05 of it,
// within the overshoot) nothing is evicted and nothing comes back, though more than 64 changes
// pass between two touches of a region (the rule before, "in use = touched in the last 64
// changes", evicted them and the robot brought them back 1.08 s later). Then robots 1-3 stop
// and robot 0 goes on alone for 4 s: their regions, idle past T, are evicted; none robot 0
// touched within T is. The map = OctoMap's.
TEST(MapResidency, TheWorkingSetIsTheLastSecondsNotTheLastChanges) {
  const std::vector<VoxelList> lists = wedge_scans();
  constexpr size_t kRobots = 4;
  const size_t per_robot = lists.size() / kRobots;
  ASSERT_GE(per_robot * kRobots, 65u) << "a robot's round must span more than 64 changes";
  struct Scan {
    size_t robot;
    const VoxelList* voxels;
  };
  std::vector<Scan> together, alone;  // all four robots twice round; then robot 0 alone, 4 s
  for (size_t round = 0; round < 2 * per_robot; ++round)
    for (size_t r = 0; r < kRobots; ++r) together.push_back({r, &lists[r * per_robot + round % per_robot]});
  for (size_t i = 0; i < 4000 / 60; ++i) alone.push_back({0, &lists[i % per_robot]});

  octomap::OcTree unbounded(0.1);
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  uint64_t peak = 0;
  for (const Scan& s : together) {
    stage.apply(unbounded, *s.voxels);
    peak = std::max<uint64_t>(peak, unbounded.memoryUsage());
  }
  for (const Scan& s : alone) stage.apply(unbounded, *s.voxels);
  const auto bound = static_cast<uint64_t>(double(peak) / 1.05);

  daemon::MapState map;
  map.tree = std::make_unique<octomap::OcTree>(0.1);
  MemorySpill spill;
  const RegionGrid grid = region_grid(daemon::evict_region_depth(test_config(0.1, true)));
  std::ostringstream log;
  daemon::MapResidency residency(map, grid, spill, bound, Log(log));
  SteppedClock clock;
  residency.set_working_set(clock.window());
  const std::chrono::milliseconds step(60);
  auto apply = [&](const Scan& s, std::chrono::milliseconds between) {
    clock.step(between);
    std::string error;
    ASSERT_TRUE(residency.touch_scan(*map.tree, *s.voxels, error, "robot-" + std::to_string(s.robot))) << error;
    stage.apply(*map.tree, *s.voxels);
    residency.enforce(*map.tree);
  };
  uint64_t most = 0;
  for (const Scan& s : together) {
    apply(s, step / kRobots);
    most = std::max<uint64_t>(most, map.tree->memoryUsage());
  }
  ASSERT_FALSE(HasFatalFailure());
  EXPECT_NEAR(residency.working_set_seconds(), 3.0, 1e-6) << "50 x a robot's 60 ms";
  daemon::MapResidencyStats st = residency.stats();
  EXPECT_GT(most, bound) << "the map must pass the bound for the rule to matter";
  EXPECT_EQ(st.evictions, 0u) << "regions touched within the last " << residency.working_set_seconds()
                              << " s were evicted";
  EXPECT_EQ(st.restores, 0u) << "regions in use went back and forth";

  std::vector<WorkingSetWindow::TimePoint> touched_at;
  for (const Scan& s : alone) {
    apply(s, step);
    touched_at.push_back(clock.now);
  }
  ASSERT_FALSE(HasFatalFailure());
  st = residency.stats();
  EXPECT_GT(st.evictions, 0u) << "the regions of the robots that stopped, idle for over 3 s, stay in memory";
  std::unordered_set<RegionId> spilled;
  for (const auto& r : residency.spilled_regions()) spilled.insert(r.id);
  const auto window = std::chrono::duration_cast<SteadyClock::duration>(std::chrono::seconds(3));
  for (size_t i = 0; i < alone.size(); ++i) {
    if (touched_at[i] <= clock.now - window) continue;
    for (const VoxelUpdate& v : *alone[i].voxels)
      ASSERT_EQ(spilled.count(region_of(grid, v.key())), 0u) << "a region robot 0 touched within T was evicted";
  }
  octomap::OcTree whole(*map.tree);
  daemon::MapResidency::fill_copy(whole, grid, residency.spilled_regions());
  const TreeDiff d = compare_leaves(whole, unbounded);
  EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels differ: " << d.first_difference;
}

// A query's restores (daemon/queries: touch_boxes, then the answer, then the bound enforced)
// make room first too (4 m boxes about each wedge's middle voxel, a bound 3/4 of the map):
// right after its restores nothing the query reads is evicted though the pass may have taken
// some of it (it comes back), and the map is OctoMap's.
TEST(MapResidency, QueryRestoresMakeRoomBeforeTheQueryReads) {
  const std::vector<VoxelList> lists = wedge_scans();
  ASSERT_GE(lists.size(), 24u);
  octomap::OcTree unbounded(0.1);
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  for (const VoxelList& l : lists) stage.apply(unbounded, l);
  const uint64_t bound = unbounded.memoryUsage() * 3 / 4;
  daemon::MapState map;
  map.tree = std::make_unique<octomap::OcTree>(0.1);
  MemorySpill spill;
  const RegionGrid grid = region_grid(daemon::evict_region_depth(test_config(0.1, true)));
  std::ostringstream log;
  daemon::MapResidency residency(map, grid, spill, bound, Log(log));
  SteppedClock clock;
  residency.set_working_set(clock.window());
  for (const VoxelList& l : lists) {
    std::string error;
    clock.step();
    ASSERT_TRUE(residency.touch_scan(*map.tree, l, error)) << error;
    stage.apply(*map.tree, l);
    residency.enforce(*map.tree);
  }
  const uint64_t restores = residency.stats().restores;
  size_t queries = 0, above = 0;
  uint64_t most = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (const VoxelList& l : lists) {  // a 4 m box about the middle voxel of each wedge
      if (l.empty()) continue;
      const octomap::OcTreeKey c = l[l.size() / 2].key();
      query::KeyBox box;
      for (unsigned a = 0; a < 3; ++a) {
        box.min[a] = static_cast<uint16_t>(c[a] - 20);
        box.max[a] = static_cast<uint16_t>(c[a] + 20);
      }
      clock.step();
      residency.touch_boxes(*map.tree, std::span<const query::KeyBox>(&box, 1));
      ASSERT_FALSE(residency.any_spilled_in(std::span<const query::KeyBox>(&box, 1))) << "the query reads it all";
      ++queries;
      above += map.tree->memoryUsage() > bound + bound / 10;
      most = std::max<uint64_t>(most, map.tree->memoryUsage());
      residency.enforce(*map.tree);  // after the answer
    }
  }
  EXPECT_GT(residency.stats().restores, restores + 20) << "queries brought regions back";
  // Measured, not a tight limit (how far a pass goes depends on the writer thread's progress):
  // with the pass 5-9 of these 78 above 1.1x, without it 9 and the most 1.23x.
  EXPECT_LE(above * 5, queries) << above << " of " << queries << " queries above 1.1x the bound before their answer";
  EXPECT_LE(most, bound + bound * 3 / 10) << double(most) / double(bound) << " of the bound before an answer";
  octomap::OcTree whole(*map.tree);
  daemon::MapResidency::fill_copy(whole, grid, residency.spilled_regions());
  const TreeDiff d = compare_leaves(whole, unbounded);
  EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels differ: " << d.first_difference;
}

// A .bt --prior (OctoMap's binary format: no values) under a bound a third of its tree: it is
// split region by region on the way in (core/file_checks/bt_file.h), never built whole, and the map is
// OctoMap's readBinary of the file with the prior's value rule (occupied at the sensor's
// clamping maximum, free at its minimum).
TEST(MapResidency, BtPriorIsLoadedWithinTheBound) {
  const std::string bt = data_file("octomap_share/geb079.bt");
  octomap::OcTree reference(0.1);
  ASSERT_TRUE(reference.readBinary(bt));
  const std::string dir = temp_dir("memory-bound-bt-prior");
  auto cfg = test_config(reference.getResolution(), true);
  cfg.map_path = dir + "/map.ot";
  cfg.max_map_memory = std::max<uint64_t>(reference.memoryUsage() / 3, 1u << 20);
  ASSERT_GT(reference.memoryUsage(), cfg.max_map_memory * 2) << "the prior must not fit the bound";
  const SensorModel& sensor = cfg.engine.sensor;
  const float occupied = octomap::logodds(sensor.clamping_max), free = octomap::logodds(sensor.clamping_min);
  for (auto it = reference.begin_tree(), end = reference.end_tree(); it != end; ++it)
    it->setLogOdds(reference.isNodeOccupied(*it) ? occupied : free);
  apply_sensor_model(reference, sensor);
  cfg.prior_path = bt;
  std::ostringstream log;
  lcm::LCM lc("memq://");
  daemon::MappingServer server(cfg, lc, log);
  const daemon::MapResidencyStats st = server.residency_stats();
  EXPECT_GT(st.evicted_regions, 0u) << log.str();
  EXPECT_EQ(st.evictions, 0u) << "the prior was built whole, then evicted: " << log.str();
  EXPECT_LE(server.with_map([](const octomap::OcTree& t) { return t.memoryUsage(); }), cfg.max_map_memory);
  const auto whole = server.whole_map();
  const TreeDiff d = compare_leaves(*whole, reference);
  EXPECT_TRUE(d.maps_equal()) << d.differing_voxels << " voxels, " << d.differing_logodds
                              << " log-odds differ: " << d.first_difference;
  EXPECT_GT(d.leaves_b, 10000u);
  EXPECT_EQ(compare_structure(*whole, reference), "");
}

}  // namespace
}  // namespace ort::test
