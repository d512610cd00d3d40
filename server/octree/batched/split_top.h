// The few nodes above the buckets that the threads update. One thread walks down to every
// bucket's node before the threads start (creating or expanding nodes on the way, as
// updateNode would), so that no two threads ever touch the same node. There is no serial
// pass afterwards: each node above the buckets counts the children it waits for, and the
// thread that finishes its last child settles it (prune, or max of the children) and
// reports to its parent, up to the root.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include <octomap/OcTree.h>

#include "octree/batched/subtree_update.h"
#include "octree/batched/voxel_buckets.h"

namespace ort {

struct PlannedSubtree {
  SubtreeRoot root;
  size_t bucket = 0;  // index into VoxelBuckets
  int parent = -1;    // index into SplitTop::nodes
};

class SplitTop {
 public:
  struct Node {
    octomap::OcTreeNode* node;
    int parent;  // -1 for the root
    bool just_created;
  };

  // The buckets lie below the root (depth >= 1); the tree's root must exist. A bucket whose
  // path runs into a pruned node that is at the clamping bound for all its voxels is left out:
  // updateNode would return early for each of them.
  SplitTop(octomap::OcTree& tree, VoxelBuckets& buckets);

  const std::vector<PlannedSubtree>& subtrees() const { return subtrees_; }

  // Called once per child (planned subtree, or node of the top) when it is done; `changed`:
  // a voxel below it was applied. The last child's thread settles the parent with
  // `node_ops`'s node methods (see subtree_update.h), and so on upwards; each prune is one
  // inner node less in `inner_nodes` (the calling thread's). Thread-safe.
  void child_done(int parent, bool changed, octomap::OcTree& node_ops, int64_t& inner_nodes);

  // Inner nodes the walk down made: leaves given their first child, pruned nodes expanded.
  int64_t inner_nodes_made() const { return inner_made_; }

 private:
  std::vector<Node> nodes_;                      // root first, each node after its parent
  std::vector<PlannedSubtree> subtrees_;         // in Morton order
  std::unique_ptr<std::atomic<int>[]> pending_;  // children not yet done, per node
  std::unique_ptr<std::atomic<bool>[]> changed_;
  int64_t inner_made_ = 0;
};

}  // namespace ort
