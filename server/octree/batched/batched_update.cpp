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

void BatchedOctreeUpdater::apply(octomap::OcTree& tree, std::span<const VoxelUpdate> updates, BatchedUpdateStats* stats,
                                 LeafChanges* changes) {
  BatchedUpdateStats local;
  BatchedUpdateStats& st = stats ? *stats : local;
  st = BatchedUpdateStats{};
  if (tree.isChangeDetectionEnabled() || updates.empty()) {
    // Only updateNodeRecurs maintains the changed-keys set.
    apply_updates_sequential(tree, updates, changes);
    return;
  }
  if (changes) changes->reset(pool_.size());
  if (!tree.getRoot()) {
    // The root can only be made through updateNode; any voxel may go first (see header).
    // Its change is read back first (order 0; the subtrees follow from 1).
    update_node_logged(tree, updates.front(), changes ? &changes->lane(0) : nullptr);
    if (changes) changes->close_segment(0, 0);
    updates = updates.subspan(1);
    if (updates.empty()) {
      if (changes) changes->finish();
      return;
    }
  }
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
      const bool changed = update_subtree(tree, node_ops, s.root, voxels, changes ? &changes->lane(worker) : nullptr);
      if (changes) changes->close_segment(worker, order[k] + 1);
      top.child_done(s.parent, changed, node_ops);
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
}

void apply_updates_batched(octomap::OcTree& tree, std::span<const VoxelUpdate> updates, unsigned threads) {
  BatchedUpdateOptions opts;
  opts.threads = threads;
  BatchedOctreeUpdater(opts).apply(tree, updates);
}

}  // namespace ort
