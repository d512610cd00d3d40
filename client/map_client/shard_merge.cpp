#include "map_client/shard_merge.h"

#include <string>

namespace ort::client {
namespace {

using octomap::OcTree;
using octomap::OcTreeNode;

// Copies src's children into dst (a node at `depth` of the merged tree, already holding
// src's value when it was made from it). At or below the region depth only one shard holds
// a node, so meeting a node there twice means two shards claim one region.
void copy_children(OcTree& dst, OcTreeNode* to, const OcTree& src, const OcTreeNode* from, unsigned depth,
                   unsigned region_depth) {
  for (unsigned i = 0; i < 8; ++i) {
    if (!src.nodeChildExists(from, i)) continue;
    const OcTreeNode* child = src.getNodeChild(from, i);
    if (dst.nodeChildExists(to, i)) {
      OcTreeNode* mine = dst.getNodeChild(to, i);
      if (depth + 1 >= region_depth || !src.nodeHasChildren(child) || !dst.nodeHasChildren(mine))
        throw ShardMergeError("two shards hold the same region (a node at depth " + std::to_string(depth + 1) +
                              "): they are not one shard set");
      copy_children(dst, mine, src, child, depth + 1, region_depth);
      continue;
    }
    OcTreeNode* made = dst.createNodeChild(to, i);
    made->setLogOdds(child->getLogOdds());
    if (src.nodeHasChildren(child)) copy_children(dst, made, src, child, depth + 1, region_depth);
  }
}

// The nodes above the region depth, bottom up, as OctoMap's updateNode leaves them: a node
// whose eight children are equal leaves is pruned, any other takes the max of its children.
void settle_above(OcTree& tree, OcTreeNode* node, unsigned depth, unsigned region_depth) {
  if (depth >= region_depth || !tree.nodeHasChildren(node)) return;
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(node, i)) settle_above(tree, tree.getNodeChild(node, i), depth + 1, region_depth);
  if (!tree.pruneNode(node)) node->updateOccupancyChildren();
}

}  // namespace

std::unique_ptr<OcTree> merge_shard_trees(std::span<const OcTree* const> shards, unsigned region_depth) {
  if (region_depth < 1 || region_depth > 16)
    throw ShardMergeError("region depth " + std::to_string(region_depth) + " is outside 1 .. 16");
  std::unique_ptr<OcTree> merged;
  for (const OcTree* s : shards) {
    if (s == nullptr) continue;
    if (!merged) {
      merged = std::make_unique<OcTree>(*s);  // the first tree whole: root, resolution, sensor model
      continue;
    }
    if (s->getResolution() != merged->getResolution())
      throw ShardMergeError("shards of resolution " + std::to_string(merged->getResolution()) + " and " +
                            std::to_string(s->getResolution()) + " m: they are not one shard set");
    if (s->getRoot() == nullptr) continue;
    if (merged->getRoot() == nullptr) {
      merged = std::make_unique<OcTree>(*s);
      continue;
    }
    if (!merged->nodeHasChildren(merged->getRoot()) || !s->nodeHasChildren(s->getRoot()))
      throw ShardMergeError("a shard's map is one leaf over the whole key space: it holds every region");
    copy_children(*merged, merged->getRoot(), *s, s->getRoot(), 0, region_depth);
  }
  if (!merged) throw ShardMergeError("no shard's map to merge");
  if (merged->getRoot()) settle_above(*merged, merged->getRoot(), 0, region_depth);
  return merged;
}

}  // namespace ort::client
