#include "octree/batched/subtree_update.h"

#include <algorithm>
#include <array>

#include "octree/batched/node_access.h"
#include "octree/batched/node_count.h"

namespace ort {
namespace {

// One node of the current root path.
struct PathNode {
  octomap::OcTreeNode* node;
  bool just_created;  // created on this path and still childless: create, never expand
  bool changed;       // a voxel below was applied: settle this node when leaving it
};

// Voxels from voxels[i] on that fill the whole subtree of a node at `depth` (8^(16 - depth)
// keys, each once, all of one state), voxels[i] being its first key; 0 when they do not.
// Sorted voxels with consecutive codes and one state are consecutive SortedVoxel values.
size_t full_block_at(std::span<const SortedVoxel> voxels, size_t i, unsigned depth) {
  const size_t block = size_t{1} << (3 * (kTreeDepth - depth));
  const SortedVoxel first = voxels[i];
  if ((sorted_voxel_code(first) & (block - 1)) != 0 || voxels.size() - i < block) return 0;
  if (voxels[i + block - 1] != first + 2 * (block - 1)) return 0;  // cheap reject before the scan
  for (size_t k = 1; k < block - 1; ++k)
    if (voxels[i + k] != first + 2 * k) return 0;
  // A key repeated after the block (a stable sort keeps it there) finds the block's leaf,
  // as it finds the pruned node in OctoMap's loop: nothing to exclude.
  return block;
}

// `leaf` (a node that stays without children) takes the update of every key of `block`; the
// change log gets each key, from the leaf's value before (0 for a node just made).
void apply_to_block(const octomap::OcTree& tree, octomap::OcTreeNode& leaf, float update,
                    std::span<const SortedVoxel> block, bool just_created, std::vector<LeafChange>* changes) {
  const float before = leaf.getLogOdds();
  update_leaf_log_odds(tree, leaf, update);
  if (changes)
    for (const SortedVoxel v : block)
      log_leaf_change(*changes, sorted_voxel_code(v), just_created, before, leaf.getLogOdds());
}

// Whether two voxels' leaves have one parent (their codes differ in the last 3 bits at most).
inline bool same_leaf_parent(SortedVoxel a, SortedVoxel b) { return (a >> 4) == (b >> 4); }

// A finest leaf takes a voxel's update, as updateNode's search-then-update does: an existing
// leaf at the clamping bound stays; a leaf just made (value 0) always takes it. Returns whether
// the leaf was applied (its parent must then be settled).
inline bool apply_to_leaf(const octomap::OcTree& tree, octomap::OcTreeNode& leaf, bool just_created, SortedVoxel v,
                          float update, std::vector<LeafChange>* changes) {
  if (!just_created && at_clamping_bound(tree, leaf, update)) return false;
  const float before = leaf.getLogOdds();  // a created leaf's 0, or an expanded node's value
  update_leaf_log_odds(tree, leaf, update);
  if (changes) log_leaf_change(*changes, sorted_voxel_code(v), just_created, before, leaf.getLogOdds());
  return true;
}

}  // namespace

bool update_subtree(const octomap::OcTree& tree, octomap::OcTree& node_ops, const SubtreeRoot& root,
                    std::span<const SortedVoxel> voxels, std::vector<LeafChange>* changes, int64_t& inner_nodes) {
  const float hit = tree.getProbHitLog();
  const float miss = tree.getProbMissLog();

  int64_t made = 0;   // nodes made by make_child_node, counted into node_ops at the end
  int64_t inner = 0;  // inner nodes made (a leaf's first child, an expansion) less those pruned
  std::array<PathNode, kTreeDepth + 1> path;
  path[root.depth] = PathNode{root.node, root.just_created, false};
  unsigned depth = root.depth;  // depth of the deepest node on the path

  // Leaves the subtrees below `target`: settles each node that changed, exactly as the last
  // updateNode through it would have (prune if all 8 children are equal leaves, else max of
  // the children), and tells its parent.
  auto leave_down_to = [&](unsigned target) {
    for (; depth > target; --depth) {
      PathNode& p = path[depth];
      if (!p.changed) continue;
      if (depth < kTreeDepth) inner -= settle_inner_node(node_ops, p.node);
      path[depth - 1].changed = true;
    }
  };

  for (size_t i = 0; i < voxels.size(); ++i) {
    SortedVoxel v = voxels[i];
    if (i > 0) leave_down_to(std::min(depth, shared_path_depth(voxels[i - 1], v)));
    const float update = sorted_voxel_occupied(v) ? hit : miss;

    // Walk down from the shared part of the path, as updateNodeRecurs does.
    for (;;) {
      PathNode& p = path[depth];
      if (depth == kTreeDepth) {
        // An existing leaf is what updateNode's search finds: at the bound, nothing happens.
        if (p.just_created || !at_clamping_bound(tree, *p.node, update)) {
          const float before = p.node->getLogOdds();  // a created leaf's 0, or an expanded node's value
          update_leaf_log_odds(tree, *p.node, update);
          if (changes) log_leaf_change(*changes, sorted_voxel_code(v), p.just_created, before, p.node->getLogOdds());
          p.changed = true;
          p.just_created = false;  // a repeated key finds this leaf as it is now
        }
        break;
      }
      const unsigned pos = child_index_at(v, depth);
      octomap::OcTreeNode* child;
      bool created = false;
      if (node_ops.nodeChildExists(p.node, pos)) {
        child = node_ops.getNodeChild(p.node, pos);
      } else if (!p.just_created && !node_ops.nodeHasChildren(p.node)) {
        // A pruned leaf: it is the deepest node search() finds on this voxel's path (its
        // value is the one the voxel had before this batch: expansions copy it unchanged).
        if (at_clamping_bound(tree, *p.node, update)) break;
        // Its whole subtree updated one way from this voxel on: OctoMap's loop expands it down
        // to every key, gives each its value + update and prunes them back into this node,
        // which ends a leaf of value + update (batched_update.h). Not the subtree's root: the
        // caller settles that one as an inner node.
        if (depth > root.depth) {
          if (const size_t block = full_block_at(voxels, i, depth)) {
            apply_to_block(tree, *p.node, update, voxels.subspan(i, block), false, changes);
            path[depth - 1].changed = true;  // final as a leaf: never settled as an inner node
            i += block - 1;
            break;
          }
        }
        node_ops.expandNode(p.node);
        ++inner;
        child = node_ops.getNodeChild(p.node, pos);
      } else {
        // A node made in this update gets its first child (any other node here has children).
        if (p.just_created && !has_child_array(*p.node)) ++inner;
        child = make_child_node(*p.node, pos);
        ++made;
        created = true;
        // A new node whose every voxel this list updates, all the same way: OctoMap's loop
        // creates its leaves, each 0 + update, and prunes them level by level back into this
        // node, which ends a leaf of that value. Made so directly (batched_update.h).
        if (depth + 1 < kTreeDepth) {
          if (const size_t block = full_block_at(voxels, i, depth + 1)) {
            apply_to_block(tree, *child, update, voxels.subspan(i, block), true, changes);
            p.changed = true;
            i += block - 1;
            break;
          }
        }
      }
      if (depth + 1 == kTreeDepth) {
        // The parent of leaves: this voxel's leaf and those of the voxels after it below the
        // same parent, without going through the path (most voxels have a sibling next).
        bool changed = apply_to_leaf(tree, *child, created, v, update, changes);
        while (i + 1 < voxels.size() && same_leaf_parent(voxels[i + 1], v)) {
          v = voxels[++i];
          const unsigned leaf_pos = child_index_at(v, depth);
          created = !node_ops.nodeChildExists(p.node, leaf_pos);  // p has its children array now
          child = created ? make_child_node(*p.node, leaf_pos) : node_ops.getNodeChild(p.node, leaf_pos);
          made += created;
          changed |= apply_to_leaf(tree, *child, created, v, sorted_voxel_occupied(v) ? hit : miss, changes);
        }
        if (changed) p.changed = true;
        break;
      }
      path[++depth] = PathNode{child, created, false};
    }
  }
  leave_down_to(root.depth);
  if (made != 0) add_to_node_count(node_ops, made);

  // The root of the subtree is settled here too; its ancestors are the caller's.
  PathNode& top = path[root.depth];
  if (top.changed && root.depth < kTreeDepth) inner -= settle_inner_node(node_ops, top.node);
  inner_nodes += inner;
  return top.changed;
}

}  // namespace ort
