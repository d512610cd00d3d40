// add_to_node_count moves OctoMap's node counter by exactly the given amount, in both
// directions, and leaves the tree's nodes alone.
#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "octree/node_count.h"
#include "support/tree_compare.h"

namespace ort {
namespace {

TEST(NodeCount, AddsAndSubtractsWithoutTouchingNodes) {
  octomap::OcTree tree(0.1), copy(0.1), helper(0.1);
  for (int i = 0; i < 50; ++i) {
    const octomap::OcTreeKey k(32768 + i, 32768 - i, 32768 + 2 * i);
    tree.updateNode(k, i % 3 != 0);
    copy.updateNode(k, i % 3 != 0);
  }
  const size_t nodes = tree.size();
  ASSERT_EQ(nodes, tree.calcNumNodes());
  const size_t helper_before = helper.size();
  for (int64_t delta : {int64_t{0}, int64_t{1}, int64_t{7}, int64_t{8}, int64_t{9}, int64_t{12345}}) {
    add_to_node_count(tree, helper, delta);
    EXPECT_EQ(tree.size(), nodes + static_cast<size_t>(delta));
    add_to_node_count(tree, helper, -delta);
    EXPECT_EQ(tree.size(), nodes);
  }
  EXPECT_EQ(counted_change(helper.size(), helper_before), 0);
  EXPECT_EQ(test::compare_structure(tree, copy), "");
  // Going below zero and back, as a counting tree's count does.
  octomap::OcTree counting(0.1);
  const size_t start = counting.size();
  add_to_node_count(counting, helper, -20);
  EXPECT_EQ(counted_change(counting.size(), start), -20);
  add_to_node_count(counting, helper, 20);
  EXPECT_EQ(counting.size(), start);
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
  int64_t created = 0;
  for (; depth < 16; ++depth) {
    const unsigned pos = octomap::computeChildIdx(far, 15 - depth);
    if (helper.nodeChildExists(node, pos)) {
      node = helper.getNodeChild(node, pos);
    } else {
      node = helper.createNodeChild(node, pos);
      ++created;
    }
  }
  ASSERT_GT(created, 0);
  double x2, y2, z2;
  tree.getMetricMax(x2, y2, z2);
  EXPECT_EQ(x2, x) << "the cached extent should still be the old one";
  add_to_node_count(tree, helper, 0);
  tree.getMetricMax(x2, y2, z2);
  EXPECT_GT(x2, x);
  // Leave the tree consistent for its destructor's sake: count the new nodes in.
  add_to_node_count(tree, helper, created);
  EXPECT_EQ(tree.size(), tree.calcNumNodes());
}

}  // namespace
}  // namespace ort
