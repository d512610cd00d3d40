// The batched stage's shortcut for leaves above the finest level (new nodes, pruned nodes)
// whose whole subtree a scan updates one way (octree/subtree_update.cpp: made a leaf of value +
// update at once, where OctoMap's loop creates or expands every leaf and prunes them back):
// checked node for node against OctoMap's updateNode loop, and the change log against
// OctoMap's search(), after every batch. The batches hold whole
// aligned blocks of 8 to 32768 keys in new space and inside pruned nodes, next to blocks
// that only just miss the shortcut: one key of the other state, one key missing, one key
// twice (the second update must find the block's leaf), blocks not aligned to their node.
#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "octree/batched/batched_update.h"
#include "octree/octree_update.h"
#include "support/leaf_change_truth.h"
#include "tree_checks.h"

namespace ort {
namespace {

using octomap::OcTree;
using octomap::OcTreeKey;

enum class Flaw { kNone, kOtherState, kMissing, kRepeated, kUnaligned };

struct BlockCounts {
  long whole_new = 0;     // whole blocks under no node yet: the shortcut on a created node
  long whole_pruned = 0;  // whole blocks inside a pruned leaf: the shortcut after expansion
  long flawed = 0;
};

// Depth of the pruned leaf (a node above the finest level without children) that covers the
// key, or -1 when there is none.
int pruned_leaf_depth(const OcTree& tree, const OcTreeKey& key) {
  const octomap::OcTreeNode* node = tree.getRoot();
  for (int depth = 0; node && depth < 16; ++depth) {
    if (!tree.nodeHasChildren(node)) return depth;
    const unsigned pos = octomap::computeChildIdx(key, 15 - depth);
    node = tree.nodeChildExists(node, pos) ? tree.getNodeChild(node, pos) : nullptr;
  }
  return -1;
}

class BlockBatches {
 public:
  explicit BlockBatches(unsigned seed) : rng_(seed) {}

  // Blocks of side 2^s (s = 1..5) at positions drawn from a small region, so that later
  // batches land on nodes earlier ones made (pruned leaves, partial subtrees).
  VoxelList next(const OcTree& before, BlockCounts& counts) {
    VoxelList list;
    std::map<uint64_t, bool> seen;  // keys of this batch: blocks may overlap
    const int blocks = pick(2, 6);
    for (int b = 0; b < blocks; ++b) {
      const int side = 1 << pick(1, 5);
      const Flaw flaw = static_cast<Flaw>(pick(0, 2) == 0 ? pick(1, 4) : 0);
      const int shift = flaw == Flaw::kUnaligned ? 1 : 0;
      const int x = 32768 - 64 + side * pick(0, 128 / side - 1) + shift, y = 32768 + side * pick(0, 64 / side - 1),
                z = 100 + side * pick(0, 64 / side - 1);
      const bool occupied = pick(0, 1) == 0;
      const size_t first = list.size();
      for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j)
          for (int k = 0; k < side; ++k) {
            const OcTreeKey key(x + i, y + j, z + k);
            if (seen.emplace(morton_code(key[0], key[1], key[2]), true).second)
              list.push_back(make_update(key, occupied));
          }
      if (list.size() == first) continue;
      const size_t victim = first + static_cast<size_t>(pick(0, static_cast<int>(list.size() - first) - 1));
      if (flaw == Flaw::kOtherState) list[victim] = make_update(list[victim].key(), !occupied);
      if (flaw == Flaw::kMissing) list.erase(list.begin() + static_cast<long>(victim));
      if (flaw == Flaw::kRepeated) {
        // Often the block's last key in Morton order: the one a repeat could hide behind.
        const OcTreeKey last(x + side - 1, y + side - 1, z + side - 1);
        list.push_back(make_update(pick(0, 1) ? last : list[victim].key(), pick(0, 1) == 0));
      }
      if (flaw != Flaw::kNone) ++counts.flawed;
      if (flaw == Flaw::kNone && list.size() - first == size_t(side) * side * side) {
        if (!before.search(OcTreeKey(x, y, z))) ++counts.whole_new;
        if (pruned_leaf_depth(before, OcTreeKey(x, y, z)) >= 0) ++counts.whole_pruned;
      }
    }
    std::shuffle(list.begin(), list.end(), rng_);
    return list;
  }

 private:
  int pick(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  std::mt19937 rng_;
};

std::vector<BatchedUpdateOptions> variants() {
  return {test::deep_buckets(1), test::deep_buckets(4), test::default_buckets()};
}

void run(unsigned seed, int batches, void (*sensor)(OcTree&), BlockCounts& counts) {
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
  BlockBatches gen(seed);
  LeafChanges log;
  std::vector<int64_t> leaves(opts.size(), 0);  // from each update's leaf count change
  for (int b = 0; b < batches; ++b) {
    const VoxelList batch = gen.next(*reference, counts);
    const test::KeyValues before = test::values_of(*reference, batch);
    apply_updates_sequential(*reference, batch);
    const test::KeyChanges truth = test::true_changes(before, test::values_of(*reference, batch));
    for (size_t v = 0; v < opts.size(); ++v) {
      // Every other batch with the change log: the shortcut logs each leaf of the block.
      const std::optional<int64_t> leaf_change = updaters[v]->apply(*trees[v], batch, nullptr, b % 2 ? &log : nullptr);
      ASSERT_TRUE(test::same_tree(*reference, *trees[v])) << "variant " << v << ", seed " << seed << ", batch " << b;
      ASSERT_TRUE(leaf_change.has_value());
      leaves[v] += *leaf_change;
      ASSERT_EQ(leaves[v], static_cast<int64_t>(reference->getNumLeafNodes())) << "leaf count, variant " << v;
      if (b % 2) {
        ASSERT_EQ(test::collapse(log), truth) << "variant " << v << ", seed " << seed << ", batch " << b;
      }
    }
  }
}

// One hit or miss reaches a clamping bound: the block's leaf is clamped, and blocks that land
// on saturated pruned nodes take OctoMap's early exit instead.
void saturating(OcTree& t) {
  t.setProbHit(0.9);
  t.setProbMiss(0.2);
  t.setClampingThresMin(0.3);
  t.setClampingThresMax(0.8);
}

int batch_count() { return test::quick_mode() ? 12 : 30; }

TEST(FullBlocks, WholeBlocksAndNearMissesMatchOctomap) {
  BlockCounts counts;
  for (unsigned seed : {1u, 2u}) run(seed, batch_count(), nullptr, counts);
  run(3, batch_count(), saturating, counts);
  std::printf("blocks: %ld whole in new space, %ld whole inside a pruned leaf, %ld with a flaw\n", counts.whole_new,
              counts.whole_pruned, counts.flawed);
  // The shortcut's cases and the near misses all came up often enough to mean something.
  EXPECT_GT(counts.whole_new, test::quick_mode() ? 10 : 40);
  EXPECT_GT(counts.whole_pruned, test::quick_mode() ? 5 : 20);
  EXPECT_GT(counts.flawed, test::quick_mode() ? 10 : 40);
}

}  // namespace
}  // namespace ort
