// Versions kept per region (octree/versions/map_version.h): after every scan of real data, and after
// random batches that prune and expand nodes above the region depth, the version built by
// rewriting only the touched regions (told by the scans' voxel lists or by the octree stage's
// log of the leaves it changed) is OctoMap's own .ot of the tree byte for byte, with its
// size and extent, and the tree made from it writes OctoMap's .bt; a version a reader holds
// does not change while the map goes on; a change not told to the builder is seen.
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "core/file_checks/octree_binary.h"
#include "octree/leaf_changes.h"
#include "octree/octree_update.h"
#include "octree/versions/map_version.h"
#include "octree/worker_pool.h"
#include "random_batches.h"
#include "real_scan_voxels.h"

namespace ort {
namespace {

std::string ot_of(const octomap::OcTree& tree) {
  std::ostringstream out(std::ios::binary);
  tree.write(out);
  return std::move(out).str();
}

// The version equals the tree: bytes, size, extent.
void expect_version_of(const MapVersion& v, const octomap::OcTree& tree, const std::string& where) {
  ASSERT_EQ(v.ot_bytes(), ot_of(tree)) << where;
  std::ostringstream streamed(std::ios::binary);
  ASSERT_TRUE(v.write_ot(streamed));
  EXPECT_EQ(streamed.str(), ot_of(tree)) << where;
  EXPECT_EQ(v.nodes(), tree.size()) << where;
  double vx, vy, vz, tx, ty, tz;
  const octomap::OcTree copy(tree);  // what a snapshot of a copy reported (const getMetricMin/Max)
  v.metric_min(vx, vy, vz);
  copy.getMetricMin(tx, ty, tz);
  EXPECT_EQ(vx, tx) << where;
  EXPECT_EQ(vy, ty) << where;
  EXPECT_EQ(vz, tz) << where;
  v.metric_max(vx, vy, vz);
  copy.getMetricMax(tx, ty, tz);
  EXPECT_EQ(vx, tx) << where;
  EXPECT_EQ(vy, ty) << where;
  EXPECT_EQ(vz, tz) << where;
}

// How a test tells the builder what changed: the scan's voxel list, or the octree stage's log of
// the leaves the update changed (what the read replica tells it).
enum class Told { kVoxels, kChangeLog };

// Applies `list` and tells the builder.
void apply_and_tell(OctreeStage& stage, octomap::OcTree& tree, const VoxelList& list, MapVersionBuilder& builder,
                    Told told) {
  LeafChanges log;
  stage.apply(tree, list, told == Told::kChangeLog ? &log : nullptr);
  if (told == Told::kChangeLog)
    builder.changed(log);
  else
    builder.changed(list);
}

class MapVersionTold : public testing::TestWithParam<Told> {};

TEST_P(MapVersionTold, EqualsOctomapsFileAfterEveryRealScanAndRewritesOnlyChangedRegions) {
  const std::vector<VoxelList> lists = test::shoot_real_scans("3dtk_dat/3dtk_3scans.graph", 3);
  if (lists.empty()) GTEST_SKIP() << "3dtk data not found";
  octomap::OcTree tree(0.1);
  tree.setProbHit(0.71);  // not the default: a tree made from a version keeps the sensor model
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  MapVersionBuilder builder(region_grid(11));
  std::shared_ptr<const MapVersion> first;
  std::string first_bytes;
  uint64_t reused = 0, merged = 0;
  // The same scans five times over: by the last passes most of the space they cross is at the
  // clamping bound, so their logs name fewer regions than their voxel lists do.
  uint64_t written_last_pass = 0, touched_last_pass = 0;
  WorkerPool pool(3);  // the regions written on three threads (the random batches below: on one)
  for (int pass = 0; pass < 5; ++pass)
    for (size_t k = 0; k < lists.size(); ++k) {
      apply_and_tell(stage, tree, lists[k], builder, GetParam());
      const auto v = builder.build(tree, &pool);
      const std::string where = "pass " + std::to_string(pass) + " scan " + std::to_string(k);
      expect_version_of(*v, tree, where);
      if (testing::Test::HasFatalFailure()) return;
      const auto f = builder.last_build();
      EXPECT_EQ(f.regions, v->regions());
      if (!first) {
        first = v, first_bytes = v->ot_bytes();
        EXPECT_EQ(f.regions_written, f.regions) << "the first build writes every region";
      } else {
        reused += f.regions - f.regions_written;
        merged += f.regions_merged;
      }
      if (pass == 4) {
        written_last_pass += f.regions_written;
        MapVersionBuilder touched(region_grid(11));
        touched.build(tree);
        touched.changed(lists[k]);
        touched.build(tree);
        touched_last_pass += touched.last_build().regions_written;
      }
    }
  EXPECT_GT(reused, 0u) << "no build kept a region it did not touch";
  EXPECT_GT(merged, 0u) << "no region was written from its old records and the changed cells";
  if (GetParam() == Told::kChangeLog)
    EXPECT_LT(written_last_pass, touched_last_pass) << "the change log named every region the voxels touch";
  else
    EXPECT_EQ(written_last_pass, touched_last_pass);
  // A reader's version stays what it was.
  EXPECT_EQ(first->ot_bytes(), first_bytes);
  // The tree made from the newest version: OctoMap's tree (its .ot) and its .bt.
  const auto v = builder.build(tree);
  const std::unique_ptr<octomap::OcTree> made = v->tree();
  EXPECT_EQ(ot_of(*made), ot_of(tree));
  EXPECT_EQ(made->getProbHitLog(), tree.getProbHitLog());
  EXPECT_EQ(octomap_binary_bytes(*made), octomap_binary_bytes(tree));
}

TEST_P(MapVersionTold, EqualsOctomapsFileWhileNodesArePrunedAndExpandedAboveTheRegionDepth) {
  // Regions of 4 keys a side: the random batches' blocks of up to 16 prune into leaves above
  // the region depth and are expanded again by single voxels. Builds after 1 to 4 batches.
  for (unsigned depth : {13u, 14u}) {
    octomap::OcTree tree(0.1);
    OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
    MapVersionBuilder builder(region_grid(depth));
    test::BatchGenerator gen(7 + depth);
    size_t coarse_leaves = 0;  // leaves above the region depth seen at builds
    for (int b = 0; b < 240; ++b) {
      const VoxelList list = gen.next();
      apply_and_tell(stage, tree, list, builder, GetParam());
      if (b % 4 == 0 || b % 7 == 3) {
        for_each_region(tree, region_grid(depth), [&](RegionId, const RegionNode& r) {
          coarse_leaves += r.depth < depth && !tree.nodeHasChildren(r.node);
        });
        const auto v = builder.build(tree);
        expect_version_of(*v, tree, "depth " + std::to_string(depth) + " batch " + std::to_string(b));
        if (testing::Test::HasFatalFailure()) return;
      }
    }
    EXPECT_GT(coarse_leaves, 0u) << "no leaf above the region depth: the case was not tried";
  }
}

INSTANTIATE_TEST_SUITE_P(VoxelsOrChangeLog, MapVersionTold, testing::Values(Told::kVoxels, Told::kChangeLog),
                         [](const testing::TestParamInfo<Told>& i) {
                           return i.param == Told::kVoxels ? std::string("Voxels") : std::string("ChangeLog");
                         });

TEST(MapVersion, AChangeNotToldIsSeenAndChangedAllRewritesIt) {
  const std::vector<VoxelList> lists = test::shoot_real_scans("3dtk_dat/3dtk_3scans.graph", 2);
  if (lists.empty()) GTEST_SKIP() << "3dtk data not found";
  octomap::OcTree tree(0.1);
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  MapVersionBuilder builder(region_grid(11));
  stage.apply(tree, lists[0]);
  builder.build(tree);
  stage.apply(tree, lists[1]);  // not told: the old regions are kept, and differ
  EXPECT_NE(builder.build(tree)->ot_bytes(), ot_of(tree));
  // An edit that does not list its keys (a box cleared node by node).
  for (double x = -1.0; x < 1.0; x += 0.1)
    for (double y = -1.0; y < 1.0; y += 0.1) tree.updateNode(x, y, 0.5, false);
  builder.changed_all();
  expect_version_of(*builder.build(tree), tree, "after changed_all");
  tree.clear();
  builder.changed_all();
  expect_version_of(*builder.build(tree), tree, "empty");
  EXPECT_EQ(builder.build(tree)->tree()->size(), 0u);
}

}  // namespace
}  // namespace ort
