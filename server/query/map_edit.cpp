#include "query/map_edit.h"

namespace ort::query {
namespace {

using Node = octomap::OcTreeNode;

// Deletes child i of `parent`, a node without children. deleteNodeChild frees only the
// node itself, and OctoMap's node destructor requires its child array to be gone, which
// stays allocated (all null) once a node's last child was deleted. expandNode then
// pruneNode is the public way to free it: 8 equal leaves made and pruned again, which also
// leaves size() exact (+8 - 8, then -1 for the node).
void delete_leaf(octomap::OcTree& tree, Node* parent, unsigned i) {
  Node* child = tree.getNodeChild(parent, i);
  tree.expandNode(child);
  tree.pruneNode(child);
  tree.deleteNodeChild(parent, i);
}

// Deletes child i of `parent` with its subtree, leaves first (deleteNodeChild counts one
// node per call, so deleting whole subtrees at once would leave size() too large).
void delete_subtree(octomap::OcTree& tree, Node* parent, unsigned i) {
  Node* child = tree.getNodeChild(parent, i);
  if (tree.nodeHasChildren(child))
    for (unsigned j = 0; j < 8; ++j)
      if (tree.nodeChildExists(child, j)) delete_subtree(tree, child, j);
  delete_leaf(tree, parent, i);
}

// The children of `node` (covering `cube`, which overlaps the box but is not inside it).
// Returns whether `node` still has children afterwards.
bool clear_unknown_below(octomap::OcTree& tree, Node* node, const NodeCube& cube, const KeyBox& box) {
  if (!tree.nodeHasChildren(node)) tree.expandNode(node);  // a pruned leaf: split to cut it
  for (unsigned i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i)) continue;
    const NodeCube c = child_cube(cube, i);
    if (overlap_voxels(c, box) == 0) continue;
    if (cube_inside(c, box) || !clear_unknown_below(tree, tree.getNodeChild(node, i), c, box))
      delete_subtree(tree, node, i);
  }
  if (!tree.nodeHasChildren(node)) return false;
  node->updateOccupancyChildren();
  return true;
}

// `node` (covering `cube`, overlapping the box but not inside it) existed before the edit
// when `existed`: a pruned leaf then stands for 8 known children and is split first; a node
// made by the edit has only the children made below it (the rest of it stays unknown).
void clear_free_below(octomap::OcTree& tree, Node* node, const NodeCube& cube, const KeyBox& box, float value,
                      bool existed) {
  if (existed && !tree.nodeHasChildren(node)) tree.expandNode(node);
  for (unsigned i = 0; i < 8; ++i) {
    const NodeCube c = child_cube(cube, i);
    if (overlap_voxels(c, box) == 0) continue;
    const bool child_existed = tree.nodeChildExists(node, i);
    if (cube_inside(c, box)) {
      if (child_existed) delete_subtree(tree, node, i);
      tree.createNodeChild(node, i)->setLogOdds(value);
      continue;
    }
    Node* child = child_existed ? tree.getNodeChild(node, i) : tree.createNodeChild(node, i);
    clear_free_below(tree, child, c, box, value, child_existed);
  }
  node->updateOccupancyChildren();
  if (tree.isNodeCollapsible(node)) tree.pruneNode(node);
}

// Every known voxel below `node` (inside the box) free: leaves get the value, inner nodes
// the children's maximum; unknown children stay unknown.
void set_known_free(octomap::OcTree& tree, Node* node, float value) {
  if (!tree.nodeHasChildren(node)) {
    node->setLogOdds(value);
    return;
  }
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(node, i)) set_known_free(tree, tree.getNodeChild(node, i), value);
  node->updateOccupancyChildren();
  if (tree.isNodeCollapsible(node)) tree.pruneNode(node);
}

// `node` (covering `cube`, overlapping the box but not inside it) exists: a pruned leaf stands
// for 8 known children and is split; missing children are unknown space and stay so.
void clear_known_free_below(octomap::OcTree& tree, Node* node, const NodeCube& cube, const KeyBox& box, float value) {
  if (!tree.nodeHasChildren(node)) tree.expandNode(node);
  for (unsigned i = 0; i < 8; ++i) {
    if (!tree.nodeChildExists(node, i)) continue;
    const NodeCube c = child_cube(cube, i);
    if (overlap_voxels(c, box) == 0) continue;
    Node* child = tree.getNodeChild(node, i);
    if (cube_inside(c, box))
      set_known_free(tree, child, value);
    else
      clear_known_free_below(tree, child, c, box, value);
  }
  node->updateOccupancyChildren();
  if (tree.isNodeCollapsible(node)) tree.pruneNode(node);
}

}  // namespace

void clear_box(octomap::OcTree& tree, const KeyBox& box, ClearTo to, Unknown unknown) {
  NodeCube root;
  root.side = 1 << tree.getTreeDepth();
  const bool whole = cube_inside(root, box);
  if (to == ClearTo::kUnknown) {
    if (!tree.getRoot()) return;
    if (whole || !clear_unknown_below(tree, tree.getRoot(), root, box)) tree.clear();
    return;
  }
  const float value = tree.getClampingThresMinLog();
  if (unknown == Unknown::kKept) {
    if (!tree.getRoot()) return;
    if (whole)
      set_known_free(tree, tree.getRoot(), value);
    else
      clear_known_free_below(tree, tree.getRoot(), root, box, value);
    return;
  }
  // OctoMap has no public way to make a root but a node update: set one voxel of the box
  // (it is overwritten below).
  if (!tree.getRoot()) tree.setNodeValue(box.min, value, /*lazy_eval=*/true);
  clear_free_below(tree, tree.getRoot(), root, box, value, /*existed=*/true);
}

void reset_map(octomap::OcTree& tree) { tree.clear(); }

}  // namespace ort::query
