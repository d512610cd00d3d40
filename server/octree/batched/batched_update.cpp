#include "octree/batched/batched_update.h"

#include <algorithm>
#include <atomic>
#include <chrono>

#include "core/clock.h"
#include "octree/batched/node_count.h"
#include "octree/batched/split_top.h"
#include "octree/batched/subtree_update.h"
#include "octree/octree_update.h"

namespace ort {
namespace {

// Buckets larger than a thread's fair share / 4 first, so the last to finish are small;
// the rest in Morton order (neighbours share the nodes above them in cache).
std::vector<size_t> work_order(const std::vector<PlannedSubtree>& subtrees, const VoxelBuckets& buckets,
                               unsigned workers) {
  std::vector<size_t> order;
  order.reserve(subtrees.size());
  const size_t large = buckets.voxels.size() / (4 * size_t{workers}) + 1;
  auto size_of = [&](size_t k) { return buckets.begin[subtrees[k].bucket + 1] - buckets.begin[subtrees[k].bucket]; };
  for (size_t k = 0; k < subtrees.size(); ++k)
    if (size_of(k) >= large) order.push_back(k);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return size_of(a) > size_of(b); });
  for (size_t k = 0; k < subtrees.size(); ++k)
    if (size_of(k) < large) order.push_back(k);
  return order;
}

}  // namespace

BatchedOctreeUpdater::BatchedOctreeUpdater(const BatchedUpdateOptions& opts)
    : opts_(opts), pool_(resolve_thread_count(opts.threads), std::nullopt, opts.helper_nice), sort_tmp_(pool_.size()) {
  // The counting trees never hold a root; the resolution is irrelevant to them.
  for (unsigned w = 0; w < pool_.size(); ++w) counting_trees_.push_back(std::make_unique<octomap::OcTree>(0.1));
}

BatchedOctreeUpdater::~BatchedOctreeUpdater() = default;

std::optional<int64_t> BatchedOctreeUpdater::apply(octomap::OcTree& tree, std::span<const VoxelUpdate> updates,
                                                   BatchedUpdateStats* stats, LeafChanges* changes) {
  BatchedUpdateStats local;
  BatchedUpdateStats& st = stats ? *stats : local;
  st = BatchedUpdateStats{};
  if (updates.empty()) {
    apply_updates_sequential(tree, updates, changes);
    return 0;
  }
  if (tree.isChangeDetectionEnabled()) {
    // Only updateNodeRecurs maintains the changed-keys set; it does not say what it made.
    apply_updates_sequential(tree, updates, changes);
    return std::nullopt;
  }
  if (changes) changes->reset(pool_.size());
  int64_t root_path_leaves = 0;  // leaves made with the root (the tree was empty)
  if (!tree.getRoot()) {
    // The root can only be made through updateNode; any voxel may go first (see header).
    // Its change is read back first (order 0; the subtrees follow from 1). The tree it makes
    // is one path (17 nodes at most): its leaves are counted, and the change below is
    // counted from there.
    update_node_logged(tree, updates.front(), changes ? &changes->lane(0) : nullptr);
    if (changes) changes->close_segment(0, 0);
    updates = updates.subspan(1);
    root_path_leaves = static_cast<int64_t>(tree.getNumLeafNodes());
    if (updates.empty()) {
      if (changes) changes->finish();
      return root_path_leaves;
    }
  }
  const auto nodes_start = static_cast<int64_t>(tree.size());
  const bool parallel = pool_.size() > 1 && updates.size() >= opts_.min_parallel_voxels;

  const auto t0 = SteadyClock::now();
  bucket_voxels(updates, opts_.buckets, parallel ? &pool_ : nullptr, buckets_, bucket_scratch_);
  const auto t1 = SteadyClock::now();
  st.bucket_ms = ms_between(t0, t1);
  st.bucket_depth = buckets_.depth;

  SplitTop top(tree, buckets_);
  const unsigned workers = parallel ? pool_.size() : 1;
  const std::vector<size_t> order = work_order(top.subtrees(), buckets_, workers);
  st.subtrees = order.size();
  const auto t2 = SteadyClock::now();
  st.top_ms = ms_between(t1, t2);

  std::atomic<size_t> next{0};
  std::vector<double> sort_ms(workers, 0.0);
  std::vector<int64_t> inner_nodes(workers, 0);                  // per worker: inner nodes made less those pruned
  const unsigned node_bits = 3 * (kTreeDepth - buckets_.depth);  // a bucket's voxels lie below one node at depth D
  auto work = [&](unsigned worker) {
    octomap::OcTree& node_ops = *counting_trees_[worker];
    for (size_t k; (k = next.fetch_add(1, std::memory_order_relaxed)) < order.size();) {
      const PlannedSubtree& s = top.subtrees()[order[k]];
      const std::span<SortedVoxel> voxels = buckets_.bucket(s.bucket);
      if (stats) {
        const auto ts = SteadyClock::now();
        sort_bucket(voxels, sort_tmp_[worker], node_bits);
        sort_ms[worker] += ms_between(ts, SteadyClock::now());
      } else {
        sort_bucket(voxels, sort_tmp_[worker], node_bits);
      }
      int64_t inner = 0;
      const bool changed =
          update_subtree(tree, node_ops, s.root, voxels, changes ? &changes->lane(worker) : nullptr, inner);
      if (changes) changes->close_segment(worker, order[k] + 1);
      top.child_done(s.parent, changed, node_ops, inner);
      inner_nodes[worker] += inner;
    }
  };
  if (parallel)
    pool_.run_shared(work);
  else
    work(0);
  const auto t3 = SteadyClock::now();
  st.subtrees_ms = ms_between(t2, t3);
  for (double ms : sort_ms) st.sort_cpu_ms += ms;
  if (changes) changes->finish();

  int64_t change = 0;
  for (auto& counting : counting_trees_) change += take_node_count(*counting);
  add_to_node_count(tree, change);
  st.node_count_change = change;

  // leaves = nodes - inner nodes, before and after.
  int64_t inner = top.inner_nodes_made();
  for (int64_t n : inner_nodes) inner += n;
  return root_path_leaves + (static_cast<int64_t>(tree.size()) - nodes_start - inner);
}

void apply_updates_batched(octomap::OcTree& tree, std::span<const VoxelUpdate> updates, unsigned threads) {
  BatchedUpdateOptions opts;
  opts.threads = threads;
  BatchedOctreeUpdater(opts).apply(tree, updates);
}

}  // namespace ort
