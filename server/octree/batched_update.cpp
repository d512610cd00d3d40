#include "octree/batched_update.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <numeric>

#include "octree/node_count.h"
#include "octree/split_top.h"
#include "octree/subtree_split.h"
#include "octree/subtree_update.h"

namespace ort {
namespace {

using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

}  // namespace

BatchedOctreeUpdater::BatchedOctreeUpdater(const BatchedUpdateOptions& opts)
    : opts_(opts), pool_(resolve_thread_count(opts.threads)) {
  // The counting trees never hold a root; the resolution is irrelevant to them.
  for (unsigned w = 1; w < pool_.size(); ++w) counting_trees_.push_back(std::make_unique<octomap::OcTree>(0.1));
}

BatchedOctreeUpdater::~BatchedOctreeUpdater() = default;

void BatchedOctreeUpdater::apply(octomap::OcTree& tree, std::span<const VoxelUpdate> updates,
                                 BatchedUpdateStats* stats) {
  BatchedUpdateStats local;
  BatchedUpdateStats& st = stats ? *stats : local;
  st = BatchedUpdateStats{};
  if (updates.empty()) return;
  if (tree.isChangeDetectionEnabled()) {
    // Only updateNodeRecurs maintains the changed-keys set.
    for (const VoxelUpdate& u : updates) tree.updateNode(u.key(), u.occupied(), /*lazy_eval=*/false);
    return;
  }
  if (!tree.getRoot()) {
    // The root can only be made through updateNode; any voxel may go first (see header).
    tree.updateNode(updates.front().key(), updates.front().occupied(), /*lazy_eval=*/false);
    updates = updates.subspan(1);
    if (updates.empty()) return;
  }

  const auto t0 = Clock::now();
  sort_voxels(updates, sorted_, sort_scratch_, opts_.sort, &pool_);
  const std::span<const SortedVoxel> voxels(sorted_);
  const auto t1 = Clock::now();
  st.sort_ms = ms_between(t0, t1);

  const unsigned workers = pool_.size();
  if (workers == 1 || voxels.size() < opts_.min_parallel_voxels) {
    update_subtree(tree, tree, SubtreeRoot{tree.getRoot(), 0, false}, voxels);
    st.subtrees = 1;
    st.subtrees_ms = ms_between(t1, Clock::now());
    return;
  }

  const size_t grain = std::max<size_t>(1, voxels.size() / (size_t{workers} * std::max(1u, opts_.subtrees_per_thread)));
  const std::vector<SubtreeRange> ranges = split_into_subtrees(voxels, grain, std::max(1u, opts_.max_split_depth));
  if (ranges.size() == 1 && ranges.front().depth == 0) {  // nothing to split (tiny grain cannot happen here)
    update_subtree(tree, tree, SubtreeRoot{tree.getRoot(), 0, false}, voxels);
    st.subtrees = 1;
    st.subtrees_ms = ms_between(t1, Clock::now());
    return;
  }
  SplitTop top = build_split_top(tree, voxels, ranges);
  st.subtrees = top.subtrees.size();
  // Largest first, so that the last ones to finish are small.
  std::vector<size_t> order(top.subtrees.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return top.subtrees[a].end - top.subtrees[a].begin > top.subtrees[b].end - top.subtrees[b].begin;
  });
  const auto t2 = Clock::now();
  st.top_ms = ms_between(t1, t2);

  // The counting trees' own counts wander from scan to scan (they also serve as the
  // fix-up's helper); only their change during this scan matters.
  std::vector<size_t> counts_before;
  for (const auto& counting : counting_trees_) counts_before.push_back(counting->size());
  std::atomic<size_t> next{0};
  pool_.run([&](unsigned worker) {
    // Worker 0 is this thread: it alone may change the tree's own counter meanwhile.
    octomap::OcTree& node_ops = worker == 0 ? tree : *counting_trees_[worker - 1];
    for (size_t k; (k = next.fetch_add(1, std::memory_order_relaxed)) < order.size();) {
      PlannedSubtree& s = top.subtrees[order[k]];
      s.changed = update_subtree(tree, node_ops, s.root, voxels.subspan(s.begin, s.end - s.begin));
    }
  });
  const auto t3 = Clock::now();
  st.subtrees_ms = ms_between(t2, t3);

  settle_split_top(tree, top);
  int64_t change = 0;
  for (size_t w = 0; w < counting_trees_.size(); ++w)
    change += counted_change(counting_trees_[w]->size(), counts_before[w]);
  add_to_node_count(tree, *counting_trees_.front(), change);
  st.node_count_change = change;
  st.settle_ms = ms_between(t3, Clock::now());
}

void apply_updates_batched(octomap::OcTree& tree, std::span<const VoxelUpdate> updates, unsigned threads) {
  BatchedUpdateOptions opts;
  opts.threads = threads;
  BatchedOctreeUpdater(opts).apply(tree, updates);
}

}  // namespace ort
