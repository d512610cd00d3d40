// The octree stage's change log (octree/leaf_changes.h) against what OctoMap's search() finds
// before and after each batch: on random batches that hit every special case of updateNode
// (created keys, leaves and pruned nodes at the clamping bound, expanded pruned nodes,
// pruning), with keys repeated in a batch, on a tree built lazily, and through the
// change-detection and updateNode-loop paths. The batched log must not depend on the
// threads or the bucket depth.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "octree/batched/batched_update.h"
#include "octree/octree_update.h"
#include "random_batches.h"
#include "support/leaf_change_truth.h"
#include "tree_checks.h"

namespace ort {
namespace {

using octomap::OcTree;
using test::collapse;
using test::KeyChanges;
using test::true_changes;
using test::values_of;

std::vector<BatchedUpdateOptions> variants() {
  return {test::deep_buckets(1), test::deep_buckets(3), test::deep_buckets(16), test::default_buckets()};
}

struct Counts {
  long created = 0, changed = 0, unchanged = 0;  // keys of the batches
};

// `repeat`: some keys of each batch appended again, in the other state, before a shuffle.
void run(unsigned seed, int batches, void (*sensor)(OcTree&), bool lazy_start, bool repeat, Counts& counts) {
  auto make = [&] {
    auto t = std::make_unique<OcTree>(0.1);
    if (sensor) sensor(*t);
    return t;
  };
  std::unique_ptr<OcTree> reference = make();
  const std::vector<BatchedUpdateOptions> opts = variants();
  std::vector<std::unique_ptr<OcTree>> trees;
  std::vector<std::unique_ptr<BatchedOctreeUpdater>> updaters;
  for (const BatchedUpdateOptions& o : opts) {
    trees.push_back(make());
    updaters.push_back(std::make_unique<BatchedOctreeUpdater>(o));
  }
  test::BatchGenerator gen(seed);
  std::mt19937 rng(seed);
  if (lazy_start) {
    for (int i = 0; i < 8; ++i) {
      const VoxelList pre = gen.next();
      for (const VoxelUpdate& u : pre) reference->updateNode(u.key(), u.occupied(), /*lazy_eval=*/true);
      for (auto& t : trees)
        for (const VoxelUpdate& u : pre) t->updateNode(u.key(), u.occupied(), /*lazy_eval=*/true);
    }
  }
  LeafChanges seq_log, log;
  for (int b = 0; b < batches; ++b) {
    VoxelList batch = gen.next();
    if (repeat) {
      const size_t n = batch.size();
      for (size_t i = 0; i < n; i += 3) batch.push_back(make_update(batch[i].key(), !batch[i].occupied()));
      std::shuffle(batch.begin(), batch.end(), rng);
    }
    const test::KeyValues before = values_of(*reference, batch);
    apply_updates_sequential(*reference, batch, &seq_log);
    const KeyChanges truth = true_changes(before, values_of(*reference, batch));
    ASSERT_EQ(collapse(seq_log), truth) << "updateNode loop, seed " << seed << ", batch " << b;
    for (const auto& [code, c] : truth) counts.created += c.was_unknown;
    counts.changed += static_cast<long>(truth.size());
    counts.unchanged += static_cast<long>(before.size() - truth.size());

    std::vector<LeafChange> first;
    for (size_t v = 0; v < opts.size(); ++v) {
      updaters[v]->apply(*trees[v], batch, nullptr, &log);
      ASSERT_TRUE(test::same_tree(*reference, *trees[v])) << "variant " << v << ", batch " << b;
      ASSERT_EQ(collapse(log), truth) << "variant " << v << ", seed " << seed << ", batch " << b;
      const std::vector<LeafChange> all = log.to_vector();
      if (v == 0) {
        first = all;
        continue;
      }
      // The same log, in the same order, whatever the threads and buckets.
      ASSERT_EQ(all.size(), first.size()) << "variant " << v << ", batch " << b;
      for (size_t i = 0; i < all.size(); ++i)
        ASSERT_TRUE(all[i].code == first[i].code && all[i].before == first[i].before && all[i].after == first[i].after)
            << "variant " << v << ", batch " << b << ", change " << i;
    }
  }
}

void tight_clamping(OcTree& t) {
  t.setClampingThresMin(0.4);
  t.setClampingThresMax(0.6);
}

void expect_meaningful(const Counts& c) {
  std::printf("keys: %ld created, %ld changed, %ld unchanged (at a clamping bound)\n", c.created, c.changed,
              c.unchanged);
  const long scale = test::quick_mode() ? 10 : 1;
  EXPECT_GT(c.created, 1000 / scale);
  EXPECT_GT(c.changed - c.created, 1000 / scale);
  EXPECT_GT(c.unchanged, 1000 / scale);
}

int batch_count() { return test::quick_mode() ? 15 : 40; }

TEST(LeafChanges, RandomBatchesMatchOctomapSearch) {
  Counts c;
  for (unsigned seed : {1u, 2u}) run(seed, batch_count(), nullptr, false, false, c);
  expect_meaningful(c);
}

TEST(LeafChanges, TightClampingAndLazyTree) {
  Counts c;
  run(3, batch_count(), tight_clamping, false, false, c);
  run(4, batch_count(), nullptr, true, false, c);
  expect_meaningful(c);
}

TEST(LeafChanges, KeysRepeatedInABatch) {
  Counts c;
  run(5, batch_count(), nullptr, false, true, c);
  run(6, batch_count(), tight_clamping, false, true, c);
  expect_meaningful(c);
}

TEST(LeafChanges, ChangeDetectionPathAndStageLogToo) {
  test::BatchGenerator gen(7);
  OcTree reference(0.1), detecting(0.1), staged(0.1);
  detecting.enableChangeDetection(true);
  BatchedOctreeUpdater updater(BatchedUpdateOptions{});
  OctreeStage stage(OctreeUpdateOptions{OctreeUpdateMode::kBatched, 3});
  LeafChanges log;
  for (int b = 0; b < 10; ++b) {
    const VoxelList batch = gen.next();
    const test::KeyValues before = values_of(reference, batch);
    apply_updates_sequential(reference, batch);
    const KeyChanges truth = true_changes(before, values_of(reference, batch));
    updater.apply(detecting, batch, nullptr, &log);
    ASSERT_EQ(collapse(log), truth) << "change detection, batch " << b;
    stage.apply(staged, batch, &log);
    ASSERT_EQ(collapse(log), truth) << "OctreeStage, batch " << b;
    ASSERT_TRUE(test::same_tree(reference, staged));
  }
  updater.apply(detecting, {}, nullptr, &log);
  EXPECT_TRUE(log.empty());
}

}  // namespace
}  // namespace ort
