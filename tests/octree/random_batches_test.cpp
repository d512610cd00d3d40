// Property test of the batched octree stage: random scan-like batches applied by OctoMap's
// updateNode loop and by the batched stage with 1, 2, 7 and 16 threads must give the same
// tree (nodes, inner values, pruned shape, counter) after every batch. The batches are made
// to hit every special case of updateNode; the test counts them on the reference tree and
// fails when a case did not occur often enough to mean anything.
#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "octree/batched/batched_update.h"
#include "octree/octree_update.h"
#include "random_batches.h"
#include "tree_checks.h"

namespace ort {
namespace {

using octomap::OcTree;
using octomap::OcTreeKey;
using test::BatchGenerator;

// How often the special cases of updateNode came up, judged on the reference tree before
// each batch.
struct CaseCounts {
  long created = 0;           // no node on the path yet
  long saturated_leaf = 0;    // finest leaf at the bound: early exit
  long saturated_pruned = 0;  // pruned node at the bound: early exit
  long expanded = 0;          // pruned node that updateNode has to expand
  long batches_pruning = 0;   // batches after which there are pruned nodes that were not there
  long edge_voxels = 0;       // keys with a coordinate 0 or 65535
};

// Deepest existing node on the key's path and its depth.
const octomap::OcTreeNode* deepest_node(const OcTree& tree, const OcTreeKey& key, unsigned& depth) {
  const octomap::OcTreeNode* node = tree.getRoot();
  depth = 0;
  while (node && depth < 16) {
    const unsigned pos = octomap::computeChildIdx(key, 15 - depth);
    if (!tree.nodeChildExists(node, pos)) return tree.nodeHasChildren(node) ? nullptr : node;
    node = tree.getNodeChild(node, pos);
    ++depth;
  }
  return node;
}

void count_cases(const OcTree& tree, const VoxelList& batch, CaseCounts& c) {
  for (const VoxelUpdate& u : batch) {
    unsigned depth;
    const octomap::OcTreeNode* node = deepest_node(tree, u.key(), depth);
    if (u.x == 0 || u.y == 0 || u.z == 0 || u.x == 65535 || u.y == 65535 || u.z == 65535) ++c.edge_voxels;
    if (!node) {
      ++c.created;
      continue;
    }
    const float l = u.occupied() ? tree.getProbHitLog() : tree.getProbMissLog();
    const bool at_bound = (l >= 0 && node->getLogOdds() >= tree.getClampingThresMaxLog()) ||
                          (l <= 0 && node->getLogOdds() <= tree.getClampingThresMinLog());
    if (depth == 16)
      c.saturated_leaf += at_bound;
    else if (at_bound)
      ++c.saturated_pruned;
    else
      ++c.expanded;
  }
}

// The pruned nodes (leaves above the finest level) as (depth, Morton code), sorted.
std::vector<std::pair<unsigned, uint64_t>> pruned_nodes(const OcTree& tree) {
  std::vector<std::pair<unsigned, uint64_t>> out;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it)
    if (it.getDepth() < 16)
      out.emplace_back(it.getDepth(), morton_code(it.getKey()[0], it.getKey()[1], it.getKey()[2]));
  std::sort(out.begin(), out.end());
  return out;
}

struct Variant {
  std::string name;
  BatchedUpdateOptions opts;
};

std::vector<Variant> variants() {
  std::vector<Variant> out;
  for (unsigned threads : {1u, 2u, 7u, 16u})
    out.push_back({std::to_string(threads) + " threads, deep buckets", test::deep_buckets(threads)});
  const BatchedUpdateOptions shallow = test::default_buckets();
  out.push_back({"7 threads, default buckets", shallow});
  BatchedUpdateOptions coarse = shallow;  // the root's 8 children as the buckets
  coarse.threads = 2;
  coarse.buckets.min_shift = 15;
  out.push_back({"2 threads, buckets at depth 1", coarse});
  return out;
}

enum class Start { kEmpty, kLazy };

void run_scenario(unsigned seed, int batches, void (*sensor)(OcTree&), Start start, CaseCounts& counts) {
  auto make = [&] {
    auto t = std::make_unique<OcTree>(0.1);
    if (sensor) sensor(*t);
    return t;
  };
  std::unique_ptr<OcTree> reference = make();
  const std::vector<Variant> vs = variants();
  std::vector<std::unique_ptr<OcTree>> trees;
  std::vector<std::unique_ptr<BatchedOctreeUpdater>> updaters;
  for (const Variant& v : vs) {
    trees.push_back(make());
    updaters.push_back(std::make_unique<BatchedOctreeUpdater>(v.opts));
  }
  BatchGenerator gen(seed);
  if (start == Start::kLazy) {
    // A tree as lazy_eval = true leaves it: stale inner values, nothing pruned.
    for (int i = 0; i < 8; ++i) {
      const VoxelList pre = gen.next();
      for (OcTree* t : {reference.get()})
        for (const VoxelUpdate& u : pre) t->updateNode(u.key(), u.occupied(), /*lazy_eval=*/true);
      for (auto& t : trees)
        for (const VoxelUpdate& u : pre) t->updateNode(u.key(), u.occupied(), /*lazy_eval=*/true);
    }
  }
  // The leaf count each update returns (no walk), kept from the start's.
  std::vector<int64_t> leaves;
  for (auto& t : trees) leaves.push_back(static_cast<int64_t>(t->getNumLeafNodes()));
  for (int b = 0; b < batches; ++b) {
    const VoxelList batch = gen.next();
    count_cases(*reference, batch, counts);
    const auto pruned_before = pruned_nodes(*reference);
    apply_updates_sequential(*reference, batch);
    const auto pruned_after = pruned_nodes(*reference);
    if (!std::includes(pruned_before.begin(), pruned_before.end(), pruned_after.begin(), pruned_after.end()))
      ++counts.batches_pruning;
    for (size_t v = 0; v < vs.size(); ++v) {
      const std::optional<int64_t> leaf_change = updaters[v]->apply(*trees[v], batch);
      ASSERT_TRUE(test::same_tree(*reference, *trees[v])) << vs[v].name << ", seed " << seed << ", batch " << b;
      ASSERT_TRUE(leaf_change.has_value());
      leaves[v] += *leaf_change;
      ASSERT_EQ(leaves[v], static_cast<int64_t>(reference->getNumLeafNodes()))
          << "leaf count, " << vs[v].name << ", seed " << seed << ", batch " << b;
    }
  }
}

int batch_count() { return test::quick_mode() ? 20 : 50; }

void expect_all_cases(const CaseCounts& c) {
  std::printf(
      "cases: %ld created, %ld saturated leaves, %ld saturated pruned, %ld expanded, %ld batches pruning, "
      "%ld edge voxels\n",
      c.created, c.saturated_leaf, c.saturated_pruned, c.expanded, c.batches_pruning, c.edge_voxels);
  // The quick variant (fewer batches, under TSan) sees fewer of the rarer cases.
  const long scale = test::quick_mode() ? 20 : 1;
  EXPECT_GT(c.created, 1000 / scale);
  EXPECT_GT(c.saturated_leaf, 1000 / scale);
  EXPECT_GT(c.saturated_pruned, 100 / scale);
  EXPECT_GT(c.expanded, 100 / scale);
  EXPECT_GT(c.batches_pruning, 5 / scale);
  EXPECT_GT(c.edge_voxels, 1000 / scale);
}

TEST(BatchedUpdate, RandomBatchesDefaultSensorModel) {
  CaseCounts counts;
  for (unsigned seed : {1u, 2u}) run_scenario(seed, batch_count(), nullptr, Start::kEmpty, counts);
  expect_all_cases(counts);
}

// One hit or miss saturates: early exits everywhere, big pruned regions flip back and forth.
void tight_clamping(OcTree& t) {
  t.setProbHit(0.9);
  t.setProbMiss(0.2);
  t.setClampingThresMin(0.3);
  t.setClampingThresMax(0.8);
}

TEST(BatchedUpdate, RandomBatchesTightClamping) {
  CaseCounts counts;
  run_scenario(3, batch_count(), tight_clamping, Start::kEmpty, counts);
  expect_all_cases(counts);
}

TEST(BatchedUpdate, RandomBatchesOnALazilyBuiltTree) {
  CaseCounts counts;
  run_scenario(4, batch_count() / 2, nullptr, Start::kLazy, counts);
  EXPECT_GT(counts.saturated_leaf + counts.expanded, 0);
}

// OctoMap's own loop gives the same tree whatever the order of a scan's keys: what the
// batched stage's reordering relies on.
TEST(BatchedUpdate, OctomapResultDoesNotDependOnKeyOrder) {
  BatchGenerator gen(9);
  OcTree shuffled(0.1), morton(0.1), reversed(0.1);
  for (int b = 0; b < batch_count(); ++b) {
    VoxelList batch = gen.next();
    apply_updates_sequential(shuffled, batch);
    std::sort(batch.begin(), batch.end(),
              [](const VoxelUpdate& a, const VoxelUpdate& c) { return make_sorted_voxel(a) < make_sorted_voxel(c); });
    apply_updates_sequential(morton, batch);
    std::reverse(batch.begin(), batch.end());
    apply_updates_sequential(reversed, batch);
    ASSERT_TRUE(test::same_tree(shuffled, morton)) << "batch " << b;
    ASSERT_TRUE(test::same_tree(shuffled, reversed)) << "batch " << b;
  }
}

TEST(BatchedUpdate, EmptyBatchAndSingleVoxel) {
  OcTree reference(0.1), batched(0.1);
  BatchedOctreeUpdater updater(BatchedUpdateOptions{});
  updater.apply(batched, {});
  EXPECT_EQ(batched.getRoot(), nullptr);
  const VoxelList one{make_update(OcTreeKey(65535, 0, 65535), true)};
  apply_updates_sequential(reference, one);
  updater.apply(batched, one);
  EXPECT_TRUE(test::same_tree(reference, batched));
}

// The engine's switch reaches the batched stage.
TEST(BatchedUpdate, ApplyUpdatesDispatchesToBatched) {
  BatchGenerator gen(12);
  OcTree reference(0.1), batched(0.1);
  OctreeUpdateOptions opts;
  opts.mode = OctreeUpdateMode::kBatched;
  opts.threads = 3;
  for (int b = 0; b < 10; ++b) {
    const VoxelList batch = gen.next();
    apply_updates_sequential(reference, batch);
    apply_updates(batched, batch, opts);
    ASSERT_TRUE(test::same_tree(reference, batched)) << "batch " << b;
  }
}

TEST(BatchedUpdate, ChangeDetectionStillRecordsKeys) {
  BatchGenerator gen(13);
  OcTree reference(0.1), batched(0.1);
  reference.enableChangeDetection(true);
  batched.enableChangeDetection(true);
  BatchedOctreeUpdater updater(BatchedUpdateOptions{});
  for (int b = 0; b < 5; ++b) {
    const VoxelList batch = gen.next();
    apply_updates_sequential(reference, batch);
    updater.apply(batched, batch);
    ASSERT_TRUE(test::same_tree(reference, batched));
    ASSERT_EQ(reference.numChangesDetected(), batched.numChangesDetected());
  }
}

}  // namespace
}  // namespace ort
