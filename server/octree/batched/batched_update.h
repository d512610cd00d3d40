// The fast CPU octree stage: one scan's voxel list applied to an octomap::OcTree in Morton
// order, one depth-first pass per subtree, subtrees on several threads. The tree ends node
// for node (leaves, log-odds, inner values, pruned shape, size()) as OctoMap's own loop of
// updateNode(key, occupied, lazy_eval = false) leaves it.
//
// Why the order does not matter: a scan's list has each key once, and an update changes
// only its own leaf and the nodes on its path. The value an update starts from is that of
// the deepest node its path finds before the batch (expanding a pruned node copies its value,
// pruning keeps it), so whether OctoMap's early exit at a clamping bound fires is fixed
// before the batch too; and every inner node ends as "pruned if its 8 children are equal
// leaves, else the max of its children", judged on its children's final state by the last
// update through it. Pruning and re-expanding in between changes nothing, because expansion
// restores exactly the 8 equal leaves that were pruned. tests/octree checks all of this
// against OctoMap, also against the list in other orders.
//
// The stage (all of it on the worker pool but the walk down to the buckets' nodes):
//   1. bucket_voxels: the list cut into the subtrees of the nodes at one depth (voxel_buckets.h)
//   2. SplitTop: the nodes above them made, one thread, a few hundred nodes at most
//   3. per bucket, largest first: sort it (it is in this thread's cache now), update_subtree,
//      and settle the nodes above when it was their last child (split_top.h)
//   4. the worker threads' net node count added to the tree's counter (node_count.h); the
//      leaf count's change is that less the inner nodes made (leaves given a first child,
//      expansions) and plus those pruned, each counted where it happens
//
// A leaf above the finest level, made by this batch (value 0) or pruned (value v), whose whole
// subtree the list updates one way (8^k keys, one state: free space near a LiDAR, mostly) is
// made a leaf of value + update at once: OctoMap's loop creates or expands its 8^k leaves,
// each value + update (none if v is at the bound), and prunes them back level by level into
// that same leaf (subtree_update.cpp). Scans that map much new space (campus-like LiDAR) have a
// large share of their voxels in such blocks (docs/history/benchmarks-log.md, "full blocks made
// at once").
//
// Trees with change detection on (enableChangeDetection) go through the plain updateNode
// loop, which also records the changed keys.
//
// The optional change log (leaf_changes.h) is written in step 3 by the thread that updates a
// leaf, and ordered by subtree afterwards.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <octomap/OcTree.h>

#include "core/voxel_update.h"
#include "octree/batched/voxel_buckets.h"
#include "octree/leaf_changes.h"
#include "octree/worker_pool.h"

namespace ort {

struct BatchedUpdateOptions {
  unsigned threads = 0;  // 0: all hardware threads
  int helper_nice = 0;   // how much the worker threads lower their priority (worker_pool.h)
  BucketOptions buckets;
  // Below this many voxels a batch is updated on the calling thread alone.
  size_t min_parallel_voxels = 16384;
};

// Where the time of the last apply() went, for tools/octree_bench.
struct BatchedUpdateStats {
  double bucket_ms = 0;    // bucket_voxels (all threads)
  double top_ms = 0;       // nodes above the buckets made (one thread)
  double subtrees_ms = 0;  // buckets sorted and updated, nodes above settled (all threads)
  double sort_cpu_ms = 0;  // of which sorting the buckets, summed over the threads
  size_t subtrees = 0;     // buckets updated
  unsigned bucket_depth = 0;
  long long node_count_change = 0;  // net nodes made by the threads
};

// Keeps the threads and buffers between scans. One apply() at a time.
class BatchedOctreeUpdater {
 public:
  explicit BatchedOctreeUpdater(const BatchedUpdateOptions& opts = {});
  ~BatchedOctreeUpdater();

  // With `changes`: reset, then filled with every finest leaf the update changed, each
  // worker writing its own lane while it updates its subtrees (leaf_changes.h).
  // Returns how the tree's leaf count (getNumLeafNodes()) changed, counted as the nodes are
  // made, expanded and pruned (no walk); none on a tree with change detection on (the
  // updateNode loop does not say).
  std::optional<int64_t> apply(octomap::OcTree& tree, std::span<const VoxelUpdate> updates,
                               BatchedUpdateStats* stats = nullptr, LeafChanges* changes = nullptr);

  unsigned threads() const { return pool_.size(); }

 private:
  BatchedUpdateOptions opts_;
  WorkerPool pool_;
  // One empty OcTree per worker: its node methods count the nodes that worker makes and
  // deletes (node_count.h). Kept because an OcTree is costly to construct.
  std::vector<std::unique_ptr<octomap::OcTree>> counting_trees_;
  std::vector<std::vector<SortedVoxel>> sort_tmp_;  // per worker
  VoxelBuckets buckets_;
  BucketScratch bucket_scratch_;
};

// One-off convenience: makes an updater (and its threads) for this call only.
void apply_updates_batched(octomap::OcTree& tree, std::span<const VoxelUpdate> updates, unsigned threads);

}  // namespace ort
