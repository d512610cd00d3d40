#include "octree/split_top.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace ort {
namespace {

// Whether any voxel of the range would pass updateNode's early exit at `node`.
bool any_voxel_applies(const octomap::OcTree& tree, const octomap::OcTreeNode& node,
                       std::span<const SortedVoxel> voxels) {
  const bool occupied_applies = !at_clamping_bound(tree, node, tree.getProbHitLog());
  const bool free_applies = !at_clamping_bound(tree, node, tree.getProbMissLog());
  return std::any_of(voxels.begin(), voxels.end(), [&](SortedVoxel v) {
    return sorted_voxel_occupied(v) ? occupied_applies : free_applies;
  });
}

}  // namespace

SplitTop build_split_top(octomap::OcTree& tree, std::span<const SortedVoxel> voxels,
                         std::span<const SubtreeRange> ranges) {
  if (!tree.getRoot()) throw std::logic_error("build_split_top: the tree has no root yet");
  SplitTop top;
  top.nodes.push_back(SplitTop::Node{tree.getRoot(), -1, false, false});
  std::array<int, kTreeDepth> path{};  // node indices on the current root path, by depth
  path[0] = 0;
  unsigned depth = 0;  // deepest node on the path

  for (size_t r = 0; r < ranges.size(); ++r) {
    const SubtreeRange& range = ranges[r];
    if (range.depth == 0) throw std::logic_error("build_split_top: a range at the root needs no split");
    const SortedVoxel first = voxels[range.begin];
    if (r > 0) {
      const unsigned shared = shared_path_depth(voxels[ranges[r - 1].begin], first);
      for (const unsigned target = std::min(depth, shared); depth > target; --depth)
        top.settle_order.push_back(path[depth]);
    }
    // Down to the range's node, the way updateNodeRecurs goes.
    for (;;) {
      const int parent = path[depth];
      octomap::OcTreeNode* node = top.nodes[parent].node;
      const unsigned pos = child_index_at(first, depth);
      octomap::OcTreeNode* child;
      bool created = false;
      if (tree.nodeChildExists(node, pos)) {
        child = tree.getNodeChild(node, pos);
      } else if (!top.nodes[parent].just_created && !tree.nodeHasChildren(node)) {
        const auto range_voxels = voxels.subspan(range.begin, range.end - range.begin);
        if (!any_voxel_applies(tree, *node, range_voxels)) break;  // all return early: skip the range
        tree.expandNode(node);
        child = tree.getNodeChild(node, pos);
      } else {
        child = tree.createNodeChild(node, pos);
        created = true;
      }
      if (depth + 1 == range.depth) {
        top.subtrees.push_back(PlannedSubtree{SubtreeRoot{child, range.depth, created}, range.begin, range.end, parent});
        break;
      }
      top.nodes.push_back(SplitTop::Node{child, parent, created, false});
      path[++depth] = static_cast<int>(top.nodes.size() - 1);
    }
  }
  for (; depth > 0; --depth) top.settle_order.push_back(path[depth]);
  top.settle_order.push_back(0);
  return top;
}

void settle_split_top(octomap::OcTree& tree, SplitTop& top) {
  for (const PlannedSubtree& s : top.subtrees)
    if (s.changed) top.nodes[s.parent].changed = true;
  for (int index : top.settle_order) {
    SplitTop::Node& n = top.nodes[index];
    if (!n.changed) continue;
    if (!tree.pruneNode(n.node)) n.node->updateOccupancyChildren();
    if (n.parent >= 0) top.nodes[n.parent].changed = true;
  }
}

}  // namespace ort
