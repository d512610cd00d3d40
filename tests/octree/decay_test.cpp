// Decay (octree/decay.h) against its rule computed independently on OctoMap's own tree: every
// stored leaf's log-odds times the factor set voxel by voxel with setNodeValue, those below
// the threshold left out, then OctoMap's updateInnerOccupancy() and prune(). On OctoMap's real
// FR-079 map and on maps of real scans with decay steps between the scans; whole sweeps and
// sweeps in small slices; until the map is empty (every node freed).
#include <cmath>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "engine/map_engine.h"
#include "octree/decay.h"
#include "octree/octree_update.h"
#include "real_scan_voxels.h"
#include "scene/scan_set.h"
#include "support/test_data.h"
#include "tree_checks.h"

namespace ort {
namespace {

// The rule on OctoMap's tree, written without octree/decay.h or octree/region.h.
std::unique_ptr<octomap::OcTree> reference_decay(const octomap::OcTree& in, float factor, float delete_below) {
  auto out = std::make_unique<octomap::OcTree>(in.getResolution());
  out->setClampingThresMin(in.getClampingThresMin());
  out->setClampingThresMax(in.getClampingThresMax());
  for (auto it = in.begin_leafs(), end = in.end_leafs(); it != end; ++it) {
    const float l = it->getLogOdds() * factor;
    if (std::fabs(l) < delete_below) continue;
    const unsigned side = 1u << (16 - it.getDepth());
    const octomap::OcTreeKey k = it.getKey();
    const unsigned lo[3] = {k[0] & ~(side - 1), k[1] & ~(side - 1), k[2] & ~(side - 1)};
    for (unsigned z = 0; z < side; ++z)
      for (unsigned y = 0; y < side; ++y)
        for (unsigned x = 0; x < side; ++x)
          out->setNodeValue(octomap::OcTreeKey(lo[0] + x, lo[1] + y, lo[2] + z), l, true);
  }
  out->updateInnerOccupancy();
  out->prune();
  return out;
}

std::unique_ptr<octomap::OcTree> copy_of(const octomap::OcTree& t) { return std::make_unique<octomap::OcTree>(t); }

TEST(Decay, FactorIsTheHalfLifeRule) {
  EXPECT_EQ(decay_factor(10, 10), 0.5f);
  EXPECT_EQ(decay_factor(0, 10), 1.0f);
  EXPECT_FLOAT_EQ(decay_factor(1, 4), static_cast<float>(std::exp2(-0.25)));
  EXPECT_THROW(decay_factor(1, 0), std::invalid_argument);
  EXPECT_THROW(decay_factor(1, -3), std::invalid_argument);
  EXPECT_THROW(decay_factor(1, NAN), std::invalid_argument);
  EXPECT_THROW(decay_factor(-1, 10), std::invalid_argument);
  EXPECT_THROW(decay_factor(INFINITY, 10), std::invalid_argument);
}

TEST(Decay, RealFr079MapEqualsTheRuleOnOctomapsTree) {
  const std::string path = test::data_file("octomap_share/geb079.bt");
  ASSERT_FALSE(path.empty());
  octomap::OcTree tree(0.08);
  ASSERT_TRUE(tree.readBinary(path));
  const DecayRule rule{decay_factor(1, 1.5), 0.9f};  // 3.5 and -2 cross 0.9 after 3 and 2 steps
  for (int step = 0; step < 4; ++step) {
    const auto expected = reference_decay(tree, rule.factor, rule.delete_below);
    // Whole sweep and a sweep in small slices give the same tree.
    auto sliced = copy_of(tree);
    DecaySweep sweep(*sliced, region_grid(10), rule);
    int slices = 0;
    while (!sweep.run_slice(*sliced, 5000)) ++slices;
    const DecayStats st = decay_tree(tree, region_grid(10), rule);
    ASSERT_TRUE(test::same_tree(*expected, tree)) << "step " << step;
    ASSERT_TRUE(test::same_tree(*expected, *sliced)) << "step " << step;
    if (step == 0) {
      EXPECT_GT(slices, 10);
      EXPECT_GT(st.leaves_decayed, 400000u);
    }
  }
  // Every value crossed the threshold: the map is empty and every node freed.
  EXPECT_EQ(tree.size(), 0u);
  EXPECT_EQ(tree.getRoot(), nullptr);
}

// Scans and decay steps interleaved: the octree stage's batched update and decay give the
// tree that OctoMap's updateNode loop and the rule on OctoMap's tree give, after every step.
void check_scans_and_steps(const std::string& graph, size_t scans, unsigned region_depth) {
  const std::vector<VoxelList> lists = test::shoot_real_scans(graph, scans);
  ASSERT_FALSE(lists.empty());
  auto reference = std::make_unique<octomap::OcTree>(0.1);
  octomap::OcTree tree(0.1);
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 2});
  const DecayRule rule{decay_factor(4, 5), 0.1f};
  uint64_t deleted = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t s = 0; s < lists.size(); ++s) {
      apply_updates_sequential(*reference, lists[s]);
      stage.apply(tree, lists[s]);
      for (int step = 0; step < 3; ++step) {
        reference = reference_decay(*reference, rule.factor, rule.delete_below);
        DecaySweep sweep(tree, region_grid(region_depth), rule);
        while (!sweep.run_slice(tree, 20000)) {}
        deleted += sweep.stats().nodes_deleted;
        ASSERT_TRUE(test::same_tree(*reference, tree))
            << graph << " pass " << pass << " scan " << s << " step " << step;
      }
    }
  }
  EXPECT_GT(deleted, 1000u);  // a miss (-0.405) falls below 0.1 in three steps of 0.57
}

TEST(Decay, RealScansWithStepsBetweenEqualTheRule) {
  check_scans_and_steps("octomap_share/scan_dat.graph", 1, 10);
  check_scans_and_steps("3dtk_dat/3dtk_3scans.graph", test::quick_mode() ? 1 : 2, 8);
}

}  // namespace
}  // namespace ort
