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
// Trees with change detection on (enableChangeDetection) go through the plain updateNode
// loop, which also records the changed keys.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include <octomap/OcTree.h>

#include "engine/voxel_update.h"
#include "octree/morton_order.h"
#include "octree/voxel_sort.h"
#include "octree/worker_pool.h"

namespace ort {

struct BatchedUpdateOptions {
  unsigned threads = 0;  // 0: all hardware threads
  SortMethod sort = SortMethod::kRadix;
  // Subtrees per thread to aim for: more balance the load better, each costs a little.
  unsigned subtrees_per_thread = 8;
  // Below this many voxels a batch is updated on the calling thread alone.
  size_t min_parallel_voxels = 16384;
  // Subtrees are cut no deeper than this (1..16): at 0.1 m a depth-12 node is a 1.6 m cube,
  // already far below any useful grain. Tests cut deeper to exercise the split.
  unsigned max_split_depth = 12;
};

// Where the time of the last apply() went, for tools/octree_bench.
struct BatchedUpdateStats {
  double sort_ms = 0;      // Morton codes and sort
  double top_ms = 0;       // split into subtrees, nodes above them made (one thread)
  double subtrees_ms = 0;  // subtrees updated (all threads)
  double settle_ms = 0;    // nodes above the split settled, node counter fixed up
  size_t subtrees = 0;
  long long node_count_change = 0;  // net nodes made by the worker threads
};

// Keeps the threads and buffers between scans. One apply() at a time.
class BatchedOctreeUpdater {
 public:
  explicit BatchedOctreeUpdater(const BatchedUpdateOptions& opts = {});
  ~BatchedOctreeUpdater();

  void apply(octomap::OcTree& tree, std::span<const VoxelUpdate> updates, BatchedUpdateStats* stats = nullptr);

  unsigned threads() const { return pool_.size(); }

 private:
  BatchedUpdateOptions opts_;
  WorkerPool pool_;
  // One empty OcTree per worker thread but the calling one: they count the nodes their
  // thread makes and deletes (node_count.h). Kept because an OcTree is costly to construct.
  std::vector<std::unique_ptr<octomap::OcTree>> counting_trees_;
  std::vector<SortedVoxel> sorted_, sort_scratch_;
};

// One-off convenience: makes an updater (and its threads) for this call only.
void apply_updates_batched(octomap::OcTree& tree, std::span<const VoxelUpdate> updates, unsigned threads);

}  // namespace ort
