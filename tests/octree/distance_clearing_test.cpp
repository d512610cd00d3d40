// Clearing by distance (octree/distance_clearing.h) against its rule computed on OctoMap's
// own tree: every leaf whose cube reaches within the radius of a centre set voxel by voxel,
// then updateInnerOccupancy() and prune(). On a map of real scans (3dtk), the centres the
// scans' own origins, whole and in slices.
#include <cmath>
#include <memory>
#include <span>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "engine/map_engine.h"
#include "octree/distance_clearing.h"
#include "octree/octree_update.h"
#include "scene/scan_set.h"
#include "support/test_data.h"
#include "tree_checks.h"

namespace ort {
namespace {

std::unique_ptr<octomap::OcTree> reference_clearing(const octomap::OcTree& in, const std::vector<octomap::point3d>& c,
                                                    double radius) {
  auto out = std::make_unique<octomap::OcTree>(in.getResolution());
  for (auto it = in.begin_leafs(), end = in.end_leafs(); it != end; ++it) {
    const double half = it.getSize() / 2;
    const octomap::point3d centre = it.getCoordinate();
    bool keep = false;
    for (const auto& p : c) {
      double d2 = 0;
      for (unsigned a = 0; a < 3; ++a) {
        const double d = std::max(0.0, std::fabs(double(p(a)) - double(centre(a))) - half);
        d2 += d * d;
      }
      keep = keep || d2 <= radius * radius;
    }
    if (!keep) continue;
    const unsigned side = 1u << (16 - it.getDepth());
    const octomap::OcTreeKey k = it.getKey();
    const unsigned lo[3] = {k[0] & ~(side - 1), k[1] & ~(side - 1), k[2] & ~(side - 1)};
    for (unsigned z = 0; z < side; ++z)
      for (unsigned y = 0; y < side; ++y)
        for (unsigned x = 0; x < side; ++x)
          out->setNodeValue(octomap::OcTreeKey(lo[0] + x, lo[1] + y, lo[2] + z), it->getLogOdds(), true);
  }
  out->updateInnerOccupancy();
  out->prune();
  return out;
}

TEST(DistanceClearing, RealScansEqualTheRuleOnOctomapsTree) {
  const std::string path = test::data_file("3dtk_dat/3dtk_3scans.graph");
  ASSERT_FALSE(path.empty());
  const ScanSet set = load_scan_graph(path);
  EngineOptions opts;
  opts.resolution = 0.1;
  opts.backend.kind = BackendKind::kCpu;
  MapEngine engine(opts);
  octomap::OcTree tree(0.1);
  std::vector<octomap::point3d> origins;
  for (size_t i = 0; i < set.scans.size() && i < (test::quick_mode() ? 1u : 2u); ++i) {
    const octomap::Pointcloud world = world_points(set.scans[i]);
    origins.push_back(sensor_origin(set.scans[i]));
    ShotScan shot;
    engine.insert(origins.back(), std::span<const octomap::point3d>(&world[0], world.size()), tree, shot);
  }
  const size_t before = tree.size();
  for (double radius : {12.0, 4.0}) {
    const auto expected = reference_clearing(tree, origins, radius);
    auto sliced = std::make_unique<octomap::OcTree>(tree);
    DistanceClearingSweep sweep(*sliced, region_grid(10), origins, radius);
    int slices = 0;
    while (!sweep.run_slice(*sliced, 100)) ++slices;
    EXPECT_GT(slices, 3);
    const uint64_t deleted = clear_beyond(tree, region_grid(10), origins, radius);
    EXPECT_GT(deleted, 0u);
    ASSERT_TRUE(test::same_tree(*expected, tree)) << radius;
    ASSERT_TRUE(test::same_tree(*expected, *sliced)) << radius;
  }
  EXPECT_LT(tree.size(), before / 2);
  // No centre: nothing cleared.
  const size_t kept = tree.size();
  EXPECT_EQ(clear_beyond(tree, region_grid(10), {}, 1.0), 0u);
  EXPECT_EQ(tree.size(), kept);
  EXPECT_THROW(clear_beyond(tree, region_grid(10), origins, 0.0), std::invalid_argument);
  EXPECT_THROW(clear_beyond(tree, region_grid(10), origins, NAN), std::invalid_argument);
}

}  // namespace
}  // namespace ort
