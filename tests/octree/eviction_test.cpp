// The memory bound's spill and restore (octree/region_codec.h, octree/region_residency.h) on
// real scans: a map built with regions spilled past a small bound and brought back when a scan
// touches them is, once everything is back, the map built without the bound, node for node
// and log-odds for log-odds (and OctoMap's own file bytes).
#include <map>
#include <memory>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "engine/map_engine.h"
#include "octree/octree_update.h"
#include "octree/region_codec.h"
#include "octree/region_residency.h"
#include "real_scan_voxels.h"
#include "scene/scan_set.h"
#include "support/test_data.h"
#include "tree_checks.h"

namespace ort {
namespace {

class MemorySpill : public RegionSpill {
 public:
  void put(RegionId id, std::span<const uint8_t> b) override { regions[id].assign(b.begin(), b.end()); }
  std::vector<uint8_t> get(RegionId id) override { return regions.at(id); }
  void erase(RegionId id) override { regions.erase(id); }
  std::map<RegionId, std::vector<uint8_t>> regions;
};

std::string ot_bytes(const octomap::OcTree& t) {
  std::ostringstream os;
  t.write(os);
  return os.str();
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
  octomap::OcTree unbounded(0.1);
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  for (int pass = 0; pass < 2; ++pass)
    for (const VoxelList& l : lists) stage.apply(unbounded, l);
  const uint64_t bound = unbounded.memoryUsage() / 3;

  octomap::OcTree bounded(0.1);
  MemorySpill spill;
  RegionResidency residency(region_grid(10), spill, bound);
  uint64_t most = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (const VoxelList& l : lists) {
      residency.touch_voxels(bounded, l);
      stage.apply(bounded, l);
      residency.enforce(bounded);
      most = std::max<uint64_t>(most, bounded.memoryUsage());
    }
  }
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

TEST(Eviction, BoundedBuildOfRealScansIsTheUnboundedMap) {
  check_bounded_build("3dtk_dat/3dtk_3scans.graph", test::quick_mode() ? 2 : 3);
}

}  // namespace
}  // namespace ort
