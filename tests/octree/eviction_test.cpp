// The memory bound's spill and restore (octree/region_codec.h, octree/region_residency.h) on
// real scans: a map built with regions spilled past a small bound and brought back when a scan
// touches them is, once everything is back, the map built without the bound, node for node
// and log-odds for log-odds (and OctoMap's own file bytes).
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "engine/map_engine.h"
#include "octree/decay.h"
#include "octree/distance_clearing.h"
#include "octree/octree_update.h"
#include "octree/region_codec.h"
#include "octree/region_residency.h"
#include "octree/region_tally.h"
#include "query/map_edit.h"
#include "real_scan_voxels.h"
#include "scene/scan_set.h"
#include "support/memory_spill.h"
#include "support/test_data.h"
#include "tree_checks.h"

namespace ort {
namespace {

using test::MemorySpill;

// A store that is slow (so the background writer lags behind and restores find regions not
// yet written) and refuses every `refuse_every`-th put (0: none).
class SlowRefusingSpill : public MemorySpill {
 public:
  explicit SlowRefusingSpill(int refuse_every) : refuse_every_(refuse_every) {}
  void put(RegionId id, std::span<const uint8_t> b) override {
    std::this_thread::sleep_for(std::chrono::microseconds(300));
    if (refuse_every_ > 0 && ++puts_ % refuse_every_ == 0) throw std::runtime_error("disk full (test)");
    MemorySpill::put(id, b);
  }

 private:
  int refuse_every_;
  int puts_ = 0;
};

std::string ot_bytes(const octomap::OcTree& t) {
  std::ostringstream os;
  t.write(os);
  return os.str();
}

// The map of `passes` passes over `lists` without a bound.
octomap::OcTree unbounded_map(OctreeStage& stage, const std::vector<VoxelList>& lists, int passes) {
  octomap::OcTree tree(0.1);
  for (int pass = 0; pass < passes; ++pass)
    for (const VoxelList& l : lists) stage.apply(tree, l);
  return tree;
}

// Stage 2's order over `passes` passes of `lists` under the bound: a scan's regions touched
// (brought back), the scan, then `after` (the bound's enforce and what the case checks).
void bounded_passes(OctreeStage& stage, RegionResidency& residency, octomap::OcTree& tree,
                    const std::vector<VoxelList>& lists, int passes, const std::function<void()>& after) {
  for (int pass = 0; pass < passes; ++pass)
    for (const VoxelList& l : lists) {
      residency.touch_voxels(tree, l);
      stage.apply(tree, l);
      after();
    }
}

TEST(Eviction, RegionBytesRoundTripAndRefuseDamage) {
  const std::vector<VoxelList> lists = test::shoot_real_scans("3dtk_dat/3dtk_3scans.graph", 1);
  ASSERT_FALSE(lists.empty());
  octomap::OcTree tree(0.1);
  apply_updates_sequential(tree, lists[0]);
  const octomap::OcTree original(tree);
  const RegionGrid grid = region_grid(10);
  size_t regions = 0;
  for (RegionId id : list_regions(tree, grid)) {
    const RegionNode r = find_region(tree, grid, id);
    if (r.depth != grid.depth || !tree.nodeHasChildren(r.node)) continue;
    const std::vector<uint8_t> bytes = encode_region(tree, grid, id);
    EXPECT_TRUE(region_bytes_intact(bytes));
    EXPECT_GT(strip_region(tree, grid, id), 0u);
    std::vector<uint8_t> damaged = bytes;
    damaged[damaged.size() / 2] ^= 0x40;
    EXPECT_THROW(restore_region(tree, grid, id, damaged), RegionCodecError);
    EXPECT_THROW(restore_region(tree, grid, id + 1, bytes), RegionCodecError);
    EXPECT_THROW(restore_region(tree, grid, id, std::span<const uint8_t>(bytes).first(bytes.size() - 5)),
                 RegionCodecError);
    restore_region(tree, grid, id, bytes);
    ++regions;
  }
  EXPECT_GT(regions, 10u);
  EXPECT_TRUE(test::same_tree(original, tree));
}

// Scans applied under a bound a third of the final map's memory: regions go and come back
// all the time; at the end, everything back, the map is the map without the bound.
void check_bounded_build(const std::string& graph, size_t scans) {
  const std::vector<VoxelList> lists = test::shoot_real_scans(graph, scans);
  ASSERT_FALSE(lists.empty());
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  const octomap::OcTree unbounded = unbounded_map(stage, lists, 2);
  const uint64_t bound = unbounded.memoryUsage() / 3;

  octomap::OcTree bounded(0.1);
  MemorySpill spill;
  RegionResidency residency(region_grid(10), spill, bound);
  uint64_t most = 0;
  bounded_passes(stage, residency, bounded, lists, 2, [&] {
    residency.enforce(bounded);
    most = std::max<uint64_t>(most, bounded.memoryUsage());
  });
  const ResidencyStats st = residency.stats();
  EXPECT_GT(st.evictions, 5u) << graph;
  EXPECT_GT(st.restores, 0u) << graph;
  EXPECT_LE(most, bound + bound / 10) << "resident memory stays within 10 % of the bound";
  EXPECT_EQ(spill.regions.size(), st.evicted_regions);
  residency.restore_all(bounded);
  EXPECT_TRUE(spill.regions.empty());
  ASSERT_TRUE(test::same_tree(unbounded, bounded)) << graph;
  EXPECT_EQ(ot_bytes(unbounded), ot_bytes(bounded));
}

// The bound's exact memory count (octree/region_tally.h) is OctoMap's memoryUsage() walk after
// every kind of change the daemon makes to its tree: scans (their regions touched first),
// evictions, restores, an edit, decay in slices with regions spilled; and it reuses the
// counts of the regions nothing changed. A change nobody tells the tally of is seen.
TEST(Eviction, ExactMemoryCountEqualsTheWalkAfterEveryChange) {
  const std::vector<VoxelList> lists = test::shoot_real_scans("3dtk_dat/3dtk_3scans.graph", 2);
  ASSERT_FALSE(lists.empty());
  octomap::OcTree tree(0.1);
  MemorySpill spill;
  const RegionGrid grid = region_grid(11);
  RegionResidency residency(grid, spill, UINT64_MAX);
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  for (const VoxelList& l : lists) {
    residency.touch_voxels(tree, l);
    stage.apply(tree, l);
    ASSERT_EQ(residency.memory(tree), tree.memoryUsage()) << "after a scan";
  }
  // Evictions down to half of the map, then a scan that brings some of it back.
  const uint64_t whole = tree.memoryUsage();
  const EnforceResult evicted = residency.enforce(tree, residency.memory(tree), whole / 2);
  EXPECT_GT(evicted.regions, 10u);
  ASSERT_EQ(residency.memory(tree), tree.memoryUsage()) << "after evictions";
  // As stage 2 does it: the scan's regions touched (restored), the scan, then a count.
  residency.touch_voxels(tree, lists[0]);
  EXPECT_GT(residency.stats().restores, 0u);
  stage.apply(tree, lists[0]);
  ASSERT_EQ(residency.memory(tree), tree.memoryUsage()) << "after a scan over restored regions";
  // Restores alone (a query's touch): everything spilled comes back.
  residency.enforce(tree, residency.memory(tree), whole / 2);
  ASSERT_GT(residency.stats().evicted_regions, 0u);
  const std::vector<RegionId> spilled = residency.spilled_ids();
  residency.touch(tree, spilled);
  ASSERT_EQ(residency.memory(tree), tree.memoryUsage()) << "after restores";
  // An edit: a box across the map back to unknown.
  const query::KeyBox box = query::key_box(tree, octomap::point3d(-3, -3, -1), octomap::point3d(4, 2, 1.5));
  residency.changed_box(box.min, box.max);
  const uint64_t before_edit = tree.memoryUsage();
  query::clear_box(tree, box, query::ClearTo::kUnknown);
  ASSERT_NE(tree.memoryUsage(), before_edit) << "the edit changes the tree's memory";
  ASSERT_EQ(residency.memory(tree), tree.memoryUsage()) << "after an edit";
  // Decay in slices over 6.4 m regions, spilled ones left on disk (they owe the step).
  residency.enforce(tree, residency.memory(tree), tree.memoryUsage() / 2);
  DecaySweep decay(tree, region_grid(10), DecayRule{0.5f, 0.6f});
  decay.regions().set_spill(residency.sweep_hooks(region_grid(10)));
  size_t slices = 0;
  while (!decay.run_slice(tree, 5'000)) {
    ++slices;
    ASSERT_EQ(residency.memory(tree), tree.memoryUsage()) << "after decay slice " << slices;
  }
  EXPECT_GT(slices, 2u);
  EXPECT_GT(decay.stats().nodes_deleted, 0u);
  ASSERT_EQ(residency.memory(tree), tree.memoryUsage()) << "after the decay's last slice";
  ASSERT_GT(residency.stats().owed_now, 0u);
  const std::vector<RegionId> owing = residency.spilled_ids();
  residency.touch(tree, owing);  // back with the step they owe applied
  ASSERT_EQ(residency.memory(tree), tree.memoryUsage()) << "after restores that applied owed steps";
  EXPECT_GT(residency.tally().regions_reused(), residency.tally().regions_recounted())
      << "most counts reuse the regions nothing changed";

  // Untold, a change inside a region goes unseen: the count is only as exact as what it is told.
  query::KeyBox small;
  for (RegionId id : list_regions(tree, grid)) {
    const RegionNode r = find_region(tree, grid, id);
    if (r.depth == grid.depth && tree.nodeHasChildren(r.node)) {
      small = query::KeyBox{region_min_key(grid, id), region_max_key(grid, id)};
      small.max[0] = static_cast<uint16_t>(small.min[0] + grid.side_keys() / 2 - 1);  // half of it
      break;
    }
  }
  const uint64_t before = residency.memory(tree);
  query::clear_box(tree, small, query::ClearTo::kUnknown);
  ASSERT_NE(tree.memoryUsage(), before);
  EXPECT_NE(residency.memory(tree), tree.memoryUsage());
}

// Eviction with the encode and the store's write on the writer thread: the map is the
// unbounded one whether a region came back from the store or from its kept nodes (before its
// bytes were written), a refused write puts the region back, and a whole-map copy taken with
// regions pending (spilled_bytes) is the whole map.
TEST(Eviction, BackgroundWritesKeepTheMapAndLoseNothingARefusedWriteHeld) {
  const std::vector<VoxelList> lists = test::shoot_real_scans("3dtk_dat/3dtk_3scans.graph", 2);
  ASSERT_FALSE(lists.empty());
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  const octomap::OcTree unbounded = unbounded_map(stage, lists, 2);
  const uint64_t bound = unbounded.memoryUsage() / 3;

  octomap::OcTree bounded(0.1);
  SlowRefusingSpill spill(7);
  const RegionGrid grid = region_grid(10);
  RegionResidency residency(grid, spill, bound);
  residency.start_background_writes(20'000);  // small: enforce also waits for room
  size_t refusals = 0, copies = 0, miscounts = 0;
  bounded_passes(stage, residency, bounded, lists, 2, [&] {
    try {
      residency.enforce(bounded, residency.memory(bounded), bound * 9 / 10);
    } catch (const std::runtime_error&) {
      ++refusals;
    }
    miscounts += residency.memory(bounded) != bounded.memoryUsage();
    // A whole-map copy while regions are pending or written (as map_snapshot.cpp takes it).
    octomap::OcTree copy(bounded);
    for (RegionId id : residency.spilled_ids()) restore_region(copy, grid, id, residency.spilled_bytes(id));
    ++copies;
  });
  EXPECT_EQ(miscounts, 0u) << "the exact count with regions pending";
  octomap::OcTree last_copy(bounded);
  for (RegionId id : residency.spilled_ids()) restore_region(last_copy, grid, id, residency.spilled_bytes(id));
  EXPECT_TRUE(test::same_tree(unbounded, last_copy)) << "a copy with regions pending is the whole map";
  const ResidencyStats st = residency.stats();
  EXPECT_GT(st.evictions, 20u);
  EXPECT_GT(st.costs.reattached, 0u) << "some restores found their region not yet let go";
  EXPECT_GT(refusals, 0u) << "refused writes reach the caller";
  residency.flush();
  residency.restore_all(bounded);
  EXPECT_TRUE(spill.regions.empty());
  ASSERT_TRUE(test::same_tree(unbounded, bounded));
  EXPECT_EQ(ot_bytes(unbounded), ot_bytes(bounded));
  EXPECT_GT(copies, 0u);
}

// The whole map from a bounded tree, as a snapshot takes it (daemon/map/map_residency.h
// fill_copy): the spilled regions' bytes put into a copy, then the steps they owe.
octomap::OcTree whole_copy(const octomap::OcTree& bounded, RegionResidency& residency) {
  octomap::OcTree copy(bounded);
  const std::vector<RegionId> ids = residency.spilled_ids();
  for (RegionId id : ids) restore_region(copy, residency.grid(), id, residency.spilled_bytes(id));
  for (RegionId id : ids) apply_owed_steps(copy, residency.grid(), id, residency.owed_steps(id), nullptr);
  return copy;
}

// Decay and clearing sweeps over a map with regions spilled leave them on disk: each owes the
// step (applied when a scan or a touch brings it back, or a copy is taken), regions wholly
// beyond the clearing radius go unread; one owing the most a region may owe comes back for the
// sweep. The map is the one the same scans and sweeps make without the bound, bit for bit.
TEST(Eviction, SweepsOwedBySpilledRegionsGiveTheUnboundedMap) {
  const std::vector<VoxelList> lists = test::shoot_real_scans("3dtk_dat/3dtk_3scans.graph", 3);
  ASSERT_FALSE(lists.empty());
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  MemorySpill spill;
  const RegionGrid sweep_grid = region_grid(10);
  RegionResidency residency(region_grid(11), spill, unbounded_map(stage, lists, 1).memoryUsage() / 3);
  residency.start_background_writes(1u << 16);
  octomap::OcTree unbounded(0.1), bounded(0.1);
  // One step of each sweep on both maps; the bounded one in slices, never restoring.
  auto decay = [&](const DecayRule& rule) {
    decay_tree(unbounded, sweep_grid, rule);
    DecaySweep sweep(bounded, sweep_grid, rule);
    sweep.regions().set_spill(residency.sweep_hooks(sweep_grid));
    while (!sweep.run_slice(bounded, 20'000)) {}
  };
  auto clear = [&](const octomap::point3d& centre, double radius) {
    clear_beyond(unbounded, sweep_grid, {centre}, radius);
    DistanceClearingSweep sweep(bounded, sweep_grid, {centre}, radius);
    sweep.regions().set_spill(residency.sweep_hooks(sweep_grid));
    while (!sweep.run_slice(bounded, 20'000)) {}
  };
  size_t k = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (const VoxelList& l : lists) {
      stage.apply(unbounded, l);
      residency.touch_voxels(bounded, l);
      stage.apply(bounded, l);
      residency.enforce(bounded);
      const uint64_t restores = residency.stats().restores;
      decay(DecayRule{0.6f, 0.45f});
      // Inner nodes too: OctoMap's file holds every node's value.
      ASSERT_EQ(ot_bytes(unbounded), ot_bytes(whole_copy(bounded, residency))) << "decayed, scan " << k;
      if (++k % 2 == 0) clear(octomap::point3d(2, 1, 0), 14);
      ASSERT_EQ(ot_bytes(unbounded), ot_bytes(whole_copy(bounded, residency))) << "cleared, scan " << k;
      ASSERT_EQ(residency.stats().restores, restores) << "a sweep brought a region back";
      if (k == 3) {  // a query's touch of half of what is spilled
        const std::vector<RegionId> ids = residency.spilled_ids();
        residency.touch(bounded, std::span<const RegionId>(ids).first(ids.size() / 2));
      }
    }
  }
  ResidencyStats st = residency.stats();
  EXPECT_GT(st.steps_owed, 50u);
  EXPECT_GT(st.owed_now, 0u);
  EXPECT_GT(st.dropped, 0u) << "regions beyond the radius deleted unread";
  // More steps than a region may owe: the sweeps bring the oldest back, and nothing is lost.
  const uint64_t restores = st.restores;
  for (size_t i = 0; i <= RegionResidency::kMaxOwed; ++i) decay(DecayRule{0.999f, 0.05f});
  st = residency.stats();
  EXPECT_GT(st.restores, restores) << "regions owing the most came back";
  EXPECT_LE(st.owed_now, st.evicted_regions * RegionResidency::kMaxOwed);
  EXPECT_EQ(ot_bytes(unbounded), ot_bytes(whole_copy(bounded, residency)));
  residency.flush();
  residency.restore_all(bounded);
  EXPECT_EQ(residency.stats().owed_now, 0u);
  ASSERT_TRUE(test::same_tree(unbounded, bounded));
  EXPECT_EQ(ot_bytes(unbounded), ot_bytes(bounded));
}

TEST(Eviction, BoundedBuildOfRealScansIsTheUnboundedMap) {
  check_bounded_build("3dtk_dat/3dtk_3scans.graph", test::quick_mode() ? 2 : 3);
}

}  // namespace
}  // namespace ort
