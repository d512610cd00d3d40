// The few nodes above the subtrees that the threads update. One thread walks down to every
// subtree's node before the threads start (creating or expanding nodes on the way, as
// updateNode would), so that no two threads ever touch the same node; after the threads are
// done it settles the nodes above them (prune, or max of the children), children first.
#pragma once

#include <span>
#include <vector>

#include <octomap/OcTree.h>

#include "octree/morton_order.h"
#include "octree/subtree_split.h"
#include "octree/subtree_update.h"

namespace ort {

struct PlannedSubtree {
  SubtreeRoot root;
  size_t begin = 0, end = 0;  // its voxels in the sorted batch
  int parent = -1;            // index into SplitTop::nodes
  bool changed = false;       // set by the thread that updated it
};

struct SplitTop {
  struct Node {
    octomap::OcTreeNode* node;
    int parent;  // -1 for the root
    bool just_created;
    bool changed;
  };
  std::vector<Node> nodes;               // root first
  std::vector<int> settle_order;         // indices into nodes, each node after its children
  std::vector<PlannedSubtree> subtrees;  // those that have voxels to apply, in Morton order
};

// `ranges` come from split_into_subtrees and lie below the root (depth >= 1); the tree's
// root must exist. A range whose path runs into a pruned node that is at the clamping bound
// for all its voxels is left out: updateNode would return early for each of them.
SplitTop build_split_top(octomap::OcTree& tree, std::span<const SortedVoxel> voxels,
                         std::span<const SubtreeRange> ranges);

// Call after every subtree ran (their `changed` set): settles each node above a changed
// subtree, with the tree's own methods, on one thread.
void settle_split_top(octomap::OcTree& tree, SplitTop& top);

}  // namespace ort
