#include "octree/batched/split_top.h"

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
  return std::any_of(voxels.begin(), voxels.end(),
                     [&](SortedVoxel v) { return sorted_voxel_occupied(v) ? occupied_applies : free_applies; });
}

}  // namespace

SplitTop::SplitTop(octomap::OcTree& tree, VoxelBuckets& buckets) {
  if (!tree.getRoot()) throw std::logic_error("SplitTop: the tree has no root yet");
  const unsigned bucket_depth = buckets.depth;
  if (bucket_depth == 0) throw std::logic_error("SplitTop: buckets at the root need no split");
  nodes_.push_back(Node{tree.getRoot(), -1, false});
  std::array<int, kTreeDepth> path{};  // node indices on the current root path, by depth
  unsigned depth = 0;                  // deepest node on the path

  for (size_t b = 0; b < buckets.count(); ++b) {
    const std::span<const SortedVoxel> voxels = buckets.bucket(b);
    const SortedVoxel first = voxels.front();
    if (b > 0) depth = std::min(depth, shared_path_depth(buckets.voxels[buckets.begin[b - 1]], first));
    // Down to the bucket's node, the way updateNodeRecurs goes.
    for (;;) {
      const int parent = path[depth];
      octomap::OcTreeNode* node = nodes_[parent].node;
      const unsigned pos = child_index_at(first, depth);
      octomap::OcTreeNode* child;
      bool created = false;
      if (tree.nodeChildExists(node, pos)) {
        child = tree.getNodeChild(node, pos);
      } else if (!nodes_[parent].just_created && !tree.nodeHasChildren(node)) {
        if (!any_voxel_applies(tree, *node, voxels)) break;  // all return early: skip the bucket
        tree.expandNode(node);
        ++inner_made_;
        child = tree.getNodeChild(node, pos);
      } else {
        if (!tree.nodeHasChildren(node)) ++inner_made_;  // a node made here gets its first child
        child = tree.createNodeChild(node, pos);
        created = true;
      }
      if (depth + 1 == bucket_depth) {
        subtrees_.push_back(PlannedSubtree{SubtreeRoot{child, bucket_depth, created}, b, parent});
        break;
      }
      nodes_.push_back(Node{child, parent, created});
      path[++depth] = static_cast<int>(nodes_.size() - 1);
    }
  }

  pending_ = std::make_unique<std::atomic<int>[]>(nodes_.size());
  changed_ = std::make_unique<std::atomic<bool>[]>(nodes_.size());
  std::vector<int> children(nodes_.size(), 0);
  for (const PlannedSubtree& s : subtrees_) ++children[s.parent];
  for (const Node& n : nodes_)
    if (n.parent >= 0) ++children[n.parent];
  for (size_t i = 0; i < nodes_.size(); ++i) {
    pending_[i].store(children[i], std::memory_order_relaxed);
    changed_[i].store(false, std::memory_order_relaxed);
  }
  // Nodes left without children (all their buckets skipped) are done, unchanged, now.
  for (size_t i = 0; i < nodes_.size(); ++i)
    if (children[i] == 0 && nodes_[i].parent >= 0) child_done(nodes_[i].parent, false, tree, inner_made_);
}

void SplitTop::child_done(int parent, bool changed, octomap::OcTree& node_ops, int64_t& inner_nodes) {
  while (parent >= 0) {
    if (changed) changed_[parent].store(true, std::memory_order_relaxed);
    // acq_rel: the last child's thread sees every other child's writes to the tree.
    if (pending_[parent].fetch_sub(1, std::memory_order_acq_rel) != 1) return;
    const Node& n = nodes_[parent];
    changed = changed_[parent].load(std::memory_order_relaxed);
    if (changed) inner_nodes -= settle_inner_node(node_ops, n.node);
    parent = n.parent;
  }
}

}  // namespace ort
