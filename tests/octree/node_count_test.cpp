// add_to_node_count moves OctoMap's node counter by exactly the given amount, in both
// directions, and leaves the tree's nodes alone; take_node_count reads what a counting tree
// counted and starts it again at zero.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "octree/batched/node_count.h"
#include "support/tree_compare.h"

namespace ort {
namespace {

TEST(NodeCount, AddsAndSubtractsWithoutTouchingNodes) {
  octomap::OcTree tree(0.1), copy(0.1);
  for (int i = 0; i < 50; ++i) {
    const octomap::OcTreeKey k(32768 + i, 32768 - i, 32768 + 2 * i);
    tree.updateNode(k, i % 3 != 0);
    copy.updateNode(k, i % 3 != 0);
  }
  const size_t nodes = tree.size();
  ASSERT_EQ(nodes, tree.calcNumNodes());
  for (int64_t delta : {int64_t{0}, int64_t{1}, int64_t{7}, int64_t{8}, int64_t{9}, int64_t{12345}}) {
    add_to_node_count(tree, delta);
    EXPECT_EQ(tree.size(), nodes + static_cast<size_t>(delta));
    add_to_node_count(tree, -delta);
    EXPECT_EQ(tree.size(), nodes);
  }
  EXPECT_EQ(test::compare_structure(tree, copy), "");
  EXPECT_TRUE(tree == copy);
}

TEST(NodeCount, CountingTreeCountsWhatItsNodeMethodsDid) {
  // A worker thread's view: nodes of `tree` made and deleted through `counting`.
  octomap::OcTree tree(0.1), counting(0.1);
  tree.updateNode(octomap::OcTreeKey(32768, 32768, 32768), true);
  EXPECT_EQ(take_node_count(counting), 0);
  octomap::OcTreeNode* root = tree.getRoot();
  octomap::OcTreeNode* child = counting.createNodeChild(root, 0);  // +1 (child 7 holds the voxel)
  counting.expandNode(child);                                      // +8
  EXPECT_EQ(take_node_count(counting), 9);
  EXPECT_EQ(counting.size(), 0u);
  counting.pruneNode(child);  // -8 (equal new leaves)
  EXPECT_EQ(take_node_count(counting), -8);
  add_to_node_count(tree, 1);
  EXPECT_EQ(tree.size(), tree.calcNumNodes());
}

TEST(NodeCount, MarksTheExtentAsChanged) {
  // getMetricMax is cached until a node is created or deleted through the tree.
  octomap::OcTree tree(0.1), helper(0.1);
  tree.updateNode(octomap::OcTreeKey(32768, 32768, 32768), true);
  double x, y, z;
  tree.getMetricMax(x, y, z);
  // Another voxel made through a different tree object, as a worker thread does.
  octomap::OcTreeNode* node = tree.getRoot();
  unsigned depth = 0;
  const octomap::OcTreeKey far(40000, 32768, 32768);
  for (; depth < 16; ++depth) {
    const unsigned pos = octomap::computeChildIdx(far, 15 - depth);
    node = helper.nodeChildExists(node, pos) ? helper.getNodeChild(node, pos) : helper.createNodeChild(node, pos);
  }
  const int64_t created = take_node_count(helper);
  ASSERT_GT(created, 0);
  double x2, y2, z2;
  tree.getMetricMax(x2, y2, z2);
  EXPECT_EQ(x2, x) << "the cached extent should still be the old one";
  add_to_node_count(tree, created);
  tree.getMetricMax(x2, y2, z2);
  EXPECT_GT(x2, x);
  EXPECT_EQ(tree.size(), tree.calcNumNodes());
}

}  // namespace
}  // namespace ort
