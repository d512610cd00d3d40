// Regions (octree/region.h) on OctoMap's real FR-079 map and on small hand-made trees: the
// walks report every stored leaf exactly once, each inside the region it is filed under,
// with OctoMap's own key, depth and value, and the bounds are OctoMap's coordinates.
#include <algorithm>
#include <memory>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "octree/region.h"
#include "support/test_data.h"

namespace ort {
namespace {

using LeafId = std::tuple<uint16_t, uint16_t, uint16_t, unsigned>;  // min-corner key, depth

LeafId leaf_id(const octomap::OcTreeKey& k, unsigned depth) { return {k[0], k[1], k[2], depth}; }

// Every stored leaf as OctoMap's iterator reports it, keyed by its min-corner key and depth.
std::vector<std::pair<LeafId, float>> octomap_leaves(const octomap::OcTree& tree) {
  std::vector<std::pair<LeafId, float>> leaves;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const unsigned depth = it.getDepth();
    const uint16_t mask = static_cast<uint16_t>(~((1u << (16 - depth)) - 1));
    const octomap::OcTreeKey k = it.getKey();
    leaves.emplace_back(leaf_id(octomap::OcTreeKey(k[0] & mask, k[1] & mask, k[2] & mask), depth), it->getLogOdds());
  }
  std::sort(leaves.begin(), leaves.end());
  return leaves;
}

std::unique_ptr<octomap::OcTree> real_map() {
  const std::string path = test::data_file("octomap_share/geb079.bt");
  if (path.empty()) return nullptr;
  auto tree = std::make_unique<octomap::OcTree>(0.08);
  if (!tree->readBinary(path)) return nullptr;
  return tree;
}

// The walks over all regions report OctoMap's leaves, each once, each in its region.
// Returns how many coarse leaves (above the region depth) were reported.
size_t check_regions_cover_tree(const octomap::OcTree& tree, unsigned depth) {
  const RegionGrid grid = region_grid(depth);
  const std::vector<std::pair<LeafId, float>> expected = octomap_leaves(tree);
  std::vector<std::pair<LeafId, float>> seen;
  size_t coarse = 0;
  std::set<RegionId> ids;
  for (RegionId id : list_regions(tree, grid)) {
    EXPECT_TRUE(ids.insert(id).second) << "region listed twice: " << id;
    const RegionBounds b = region_bounds(tree, grid, id);
    for_each_leaf_in_region(tree, grid, id, [&](const RegionLeaf& leaf) {
      if (leaf.depth < grid.depth) {
        ++coarse;  // covers its region: the region's min corner lies inside it
        EXPECT_EQ(region_of(grid, leaf.key), id);
      } else {
        EXPECT_EQ(region_of(grid, leaf.key), id);
        for (unsigned a = 0; a < 3; ++a) {
          EXPECT_GE(leaf.key[a], b.min_key[a]);
          EXPECT_LE(leaf.key[a] + (1u << (16 - leaf.depth)) - 1, b.max_key[a]);
          const double centre = tree.keyToCoord(leaf.key[a], leaf.depth);
          EXPECT_GT(centre, b.min(a));
          EXPECT_LT(centre, b.max(a));
        }
      }
      seen.emplace_back(leaf_id(leaf.key, leaf.depth), leaf.node->getLogOdds());
    });
  }
  std::sort(seen.begin(), seen.end());  // a leaf reported twice makes seen longer
  EXPECT_EQ(seen, expected) << "depth " << depth;
  EXPECT_FALSE(ids.empty());
  return coarse;
}

TEST(Region, IdsAndBoundsFollowOctomapKeys) {
  octomap::OcTree tree(0.1);
  const RegionGrid grid = region_grid(10);
  EXPECT_EQ(grid.side_keys(), 64u);
  const octomap::OcTreeKey k = tree.coordToKey(octomap::point3d(1.23f, -4.5f, 0.7f));
  const RegionId id = region_of(grid, k);
  const RegionBounds b = region_bounds(tree, grid, id);
  for (unsigned a = 0; a < 3; ++a) {
    EXPECT_EQ(b.min_key[a] % 64, 0);
    EXPECT_EQ(b.max_key[a], b.min_key[a] + 63);
    EXPECT_LE(b.min_key[a], k[a]);
    EXPECT_GE(b.max_key[a], k[a]);
    EXPECT_NEAR(b.max(a) - b.min(a), 6.4, 1e-4);
  }
  // A key one past the max corner is in the next region along that axis.
  octomap::OcTreeKey next = b.max_key;
  next[1] = static_cast<uint16_t>(next[1] + 1);
  EXPECT_EQ(region_of(grid, next), id + (RegionId(1) << 16));
  EXPECT_EQ(region_min_key(grid, region_of(grid, b.max_key)), b.min_key);
  // OctoMap's node at the region depth is the region's root.
  tree.updateNode(k, true);
  const RegionNode r = find_region(tree, grid, id);
  ASSERT_NE(r.node, nullptr);
  EXPECT_EQ(r.depth, 10u);
  EXPECT_EQ(r.node, tree.search(k, 10));
  EXPECT_EQ(find_region(tree, grid, id + 1).node, nullptr);
  EXPECT_THROW(region_grid(0), std::invalid_argument);
  EXPECT_THROW(region_grid(17), std::invalid_argument);
}

TEST(Region, CoarseLeafIsReportedOnceForAllItsRegions) {
  octomap::OcTree tree(0.1);
  // Eight equal finest siblings, pruned: one stored leaf at depth 15 over 8 depth-16 regions.
  const octomap::OcTreeKey k(32768, 32768, 32768);
  for (unsigned i = 0; i < 8; ++i)
    tree.setNodeValue(octomap::OcTreeKey(k[0] + (i & 1), k[1] + (i >> 1 & 1), k[2] + (i >> 2 & 1)), 2.0f);
  tree.setNodeValue(octomap::OcTreeKey(k[0] + 9, k[1], k[2]), -1.0f);  // a finest leaf nearby
  tree.prune();
  const octomap::OcTreeNode* coarse = tree.search(k, 15);
  ASSERT_NE(coarse, nullptr);
  ASSERT_FALSE(tree.nodeHasChildren(coarse));
  const RegionGrid grid = region_grid(16);
  const std::vector<RegionId> ids = list_regions(tree, grid);
  ASSERT_EQ(ids.size(), 2u);  // the coarse leaf once, the finest leaf
  EXPECT_EQ(ids[0], region_of(grid, k));
  // Each of the 8 regions it covers finds it.
  for (unsigned i = 0; i < 8; ++i) {
    const octomap::OcTreeKey ki(k[0] + (i & 1), k[1] + (i >> 1 & 1), k[2] + (i >> 2 & 1));
    const RegionNode r = find_region(tree, grid, region_of(grid, ki));
    EXPECT_EQ(r.node, coarse);
    EXPECT_EQ(r.depth, 15u);
  }
  check_regions_cover_tree(tree, 16);
  check_regions_cover_tree(tree, 12);
}

TEST(Region, WalksCoverOctomapsRealMapAtEveryDepth) {
  const auto tree = real_map();
  ASSERT_NE(tree, nullptr);
  // Coarse leaves are those above the region depth, as OctoMap's iterator counts them.
  for (unsigned depth : {8u, 14u, 16u}) {
    size_t above = 0;
    for (auto it = tree->begin_leafs(), end = tree->end_leafs(); it != end; ++it) above += it.getDepth() < depth;
    EXPECT_EQ(check_regions_cover_tree(*tree, depth), above) << depth;
    if (depth > 13) {
      EXPECT_GT(above, 0u);  // its pruned free space has leaves at depth 13
    }
  }
}

TEST(Region, EmptyTreeHasNoRegions) {
  octomap::OcTree tree(0.1);
  EXPECT_TRUE(list_regions(tree, region_grid(10)).empty());
  int n = 0;
  for_each_leaf_in_region(tree, region_grid(10), 0, [&](const RegionLeaf&) { ++n; });
  EXPECT_EQ(n, 0);
}

}  // namespace
}  // namespace ort
