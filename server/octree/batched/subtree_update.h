// The batched update of one subtree: Morton-sorted voxels applied in one depth-first pass.
//
// OctoMap's updateNode walks root to leaf twice per voxel (search, then the update) and on
// the way back up tries to prune, or re-computes the max of the children, at every level.
// Here consecutive voxels keep the part of the path they share; a node is settled (pruned
// or given the max of its children) once, when the pass leaves its subtree, and only when
// some voxel below it was applied. The result is node for node what the updateNode loop
// gives (see batched_update.h for why the order of the voxels does not matter).
#pragma once

#include <cstdint>
#include <limits>
#include <span>

#include <octomap/OcTree.h>

#include "octree/batched/morton_order.h"
#include "octree/leaf_changes.h"

namespace ort {

// Where the pass starts: a node that exists and the depth it sits at (0 = root).
struct SubtreeRoot {
  octomap::OcTreeNode* node = nullptr;
  unsigned depth = 0;
  // Created by this batch above the split and still without children: its missing children
  // are created one by one, not expanded from it (OctoMap's node_just_created).
  bool just_created = false;
};

// Applies `voxels` (sorted, all inside the subtree of `root`) to the tree and settles every
// node of the subtree they touch, `root` included. Returns whether any voxel was applied,
// i.e. whether root's ancestors must be settled too.
//
// Values and the sensor model come from `tree` (updateNodeLogOdds, read only). Nodes are
// expanded and pruned through `node_ops`, and created as createNodeChild does (node_access.h)
// and counted into it, `node_ops` being `tree` itself or, when several
// threads update one tree, the thread's own OcTree that only counts the nodes (OctoMap's node
// counter is a plain size_t; see node_count.h).
//
// With `changes`, every finest leaf whose value the pass changed is appended to it, in the
// voxels' order (leaf_changes.h), also each key of a block made a single leaf at once
// (batched_update.h).
//
// `inner_nodes` gets the net number of inner nodes (nodes with children) the pass made: with
// the node count's change it gives the leaf count's (leaves = nodes - inner nodes), so the
// daemon keeps OctoMap's getNumLeafNodes() without walking the tree (batched_update.h).
bool update_subtree(const octomap::OcTree& tree, octomap::OcTree& node_ops, const SubtreeRoot& root,
                    std::span<const SortedVoxel> voxels, std::vector<LeafChange>* changes, int64_t& inner_nodes);

// Whether OctoMap's updateNode would return early for an update of `log_odds_update` that
// finds `node` as the deepest existing node on its path: already at the clamping bound in
// the update's direction (OccupancyOcTreeBase::updateNode).
inline bool at_clamping_bound(const octomap::OcTree& tree, const octomap::OcTreeNode& node, float log_odds_update) {
  const float v = node.getLogOdds();
  return (log_odds_update >= 0 && v >= tree.getClampingThresMaxLog()) ||
         (log_odds_update <= 0 && v <= tree.getClampingThresMinLog());
}

// updateNodeLogOdds of OctoMap's OccupancyOcTreeBase inlined (it is virtual and calls the
// library's out-of-line addValue; this runs once per voxel): the same float addition, then
// the same clamping comparisons. OcTree does not override it; tests/octree compares every
// map with OctoMap's own.
inline void update_leaf_log_odds(const octomap::OcTree& tree, octomap::OcTreeNode& leaf, float update) {
  const float v = leaf.getLogOdds() + update;
  if (v < tree.getClampingThresMinLog())
    leaf.setLogOdds(tree.getClampingThresMinLog());
  else if (v > tree.getClampingThresMaxLog())
    leaf.setLogOdds(tree.getClampingThresMaxLog());
  else
    leaf.setLogOdds(v);
}

// Settles an inner node whose subtree changed, as the last updateNode through it leaves it:
// pruned when its 8 children are leaves of one value (pruneNode), else the max of its
// children's log-odds (updateOccupancyChildren). One read of the children decides both,
// with isNodeCollapsible's and getMaxChildLogOdds's comparisons; the prune itself goes
// through `node_ops` (it frees the children and counts them), which checks again. Returns
// whether it pruned (the node is a leaf now).
inline bool settle_inner_node(octomap::OcTree& node_ops, octomap::OcTreeNode* node) {
  float max = -std::numeric_limits<float>::max();
  bool collapsible = true;
  float first = 0;
  for (unsigned i = 0; i < 8; ++i) {
    if (!node_ops.nodeChildExists(node, i)) {
      collapsible = false;
      continue;
    }
    const octomap::OcTreeNode* child = node_ops.getNodeChild(node, i);
    const float l = child->getLogOdds();
    if (l > max) max = l;
    if (i == 0) first = l;
    // Once a child decides against the prune, only the max is left to find.
    if (collapsible && (!(l == first) || node_ops.nodeHasChildren(child))) collapsible = false;
  }
  if (collapsible && node_ops.pruneNode(node)) return true;
  node->setLogOdds(max);
  return false;
}

}  // namespace ort
