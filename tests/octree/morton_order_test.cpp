// Morton codes follow OctoMap's own child order, and both sorts give the same order.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>
#include <octomap/OcTreeKey.h>

#include "octree/morton_order.h"
#include "octree/voxel_sort.h"
#include "octree/subtree_split.h"

namespace ort {
namespace {

TEST(MortonOrder, ChildIndicesAreOctomapsAtEveryDepth) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> key(0, 65535);
  for (int i = 0; i < 20000; ++i) {
    const VoxelUpdate u = make_update(octomap::OcTreeKey(key(rng), key(rng), key(rng)), i % 2 == 0);
    const SortedVoxel v = make_sorted_voxel(u);
    EXPECT_EQ(sorted_voxel_occupied(v), u.occupied());
    for (unsigned depth = 0; depth < kTreeDepth; ++depth)
      ASSERT_EQ(child_index_at(v, depth), octomap::computeChildIdx(u.key(), kTreeDepth - 1 - depth))
          << "depth " << depth;
    uint16_t x, y, z;
    morton_decode(sorted_voxel_code(v), x, y, z);
    EXPECT_EQ(x, u.x);
    EXPECT_EQ(y, u.y);
    EXPECT_EQ(z, u.z);
  }
}

TEST(MortonOrder, KeyRangeEdges) {
  EXPECT_EQ(morton_code(0, 0, 0), 0u);
  EXPECT_EQ(morton_code(65535, 65535, 65535), (uint64_t{1} << 48) - 1);
  EXPECT_EQ(morton_code(1, 0, 0), 1u);
  EXPECT_EQ(morton_code(0, 1, 0), 2u);
  EXPECT_EQ(morton_code(0, 0, 1), 4u);
  EXPECT_EQ(morton_code(32768, 0, 0), uint64_t{1} << 45);
  EXPECT_EQ(morton_code(0, 0, 32768), uint64_t{1} << 47);
}

// The depth where two keys' root paths part, found the slow way.
unsigned shared_depth_by_walk(const octomap::OcTreeKey& a, const octomap::OcTreeKey& b) {
  unsigned depth = 0;
  while (depth < kTreeDepth - 1 &&
         octomap::computeChildIdx(a, kTreeDepth - 1 - depth) == octomap::computeChildIdx(b, kTreeDepth - 1 - depth))
    ++depth;
  return depth;
}

TEST(MortonOrder, SharedPathDepth) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> key(0, 65535), small(0, 3);
  for (int i = 0; i < 20000; ++i) {
    const octomap::OcTreeKey a(key(rng), key(rng), key(rng));
    // Neighbours share long paths; random keys short ones.
    const octomap::OcTreeKey b = i % 2 ? octomap::OcTreeKey(key(rng), key(rng), key(rng))
                                       : octomap::OcTreeKey(a[0] ^ small(rng), a[1] ^ small(rng), a[2] ^ 1);
    if (a == b) continue;
    const SortedVoxel va = make_sorted_voxel(make_update(a, true)), vb = make_sorted_voxel(make_update(b, false));
    ASSERT_EQ(shared_path_depth(va, vb), shared_depth_by_walk(a, b));
  }
}

VoxelList random_unique_list(std::mt19937& rng, size_t n, int lo, int hi) {
  std::uniform_int_distribution<int> key(lo, hi);
  VoxelList list;
  octomap::KeySet seen;
  while (list.size() < n) {
    const octomap::OcTreeKey k(key(rng), key(rng), key(rng));
    if (seen.insert(k).second) list.push_back(make_update(k, rng() % 3 == 0));
  }
  return list;
}

TEST(MortonOrder, RadixSortEqualsStdSort) {
  std::mt19937 rng(3);
  WorkerPool pool(3);
  for (auto [n, lo, hi] : {std::tuple{0, 0, 1}, {1, 0, 65535}, {1000, 32700, 32800}, {200000, 0, 65535},
                           {100000, 32000, 33000}, {60000, 32760, 32800}, {50000, 0, 40}}) {
    const VoxelList list = random_unique_list(rng, n, lo, hi);
    std::vector<SortedVoxel> radix, pooled, standard, scratch;
    sort_voxels(list, radix, scratch, SortMethod::kRadix);
    sort_voxels(list, pooled, scratch, SortMethod::kRadix, &pool);
    sort_voxels(list, standard, scratch, SortMethod::kStd);
    ASSERT_EQ(radix, standard) << n << " voxels in [" << lo << "," << hi << "]";
    ASSERT_EQ(pooled, standard) << n << " voxels in [" << lo << "," << hi << "], 3 threads";
    ASSERT_TRUE(std::is_sorted(radix.begin(), radix.end()));
    ASSERT_EQ(radix.size(), list.size());
  }
}

TEST(SubtreeSplit, RangesAreDisjointSubtreesCoveringAll) {
  std::mt19937 rng(5);
  const VoxelList list = random_unique_list(rng, 50000, 32600, 32900);
  std::vector<SortedVoxel> sorted, scratch;
  sort_voxels(list, sorted, scratch);
  for (size_t grain : {size_t{1}, size_t{100}, size_t{5000}, size_t{1000000}}) {
    for (unsigned max_depth : {1u, 4u, 12u, 16u}) {
      const std::vector<SubtreeRange> ranges = split_into_subtrees(sorted, grain, max_depth);
      ASSERT_FALSE(ranges.empty());
      size_t next = 0;
      for (const SubtreeRange& r : ranges) {
        ASSERT_EQ(r.begin, next);
        ASSERT_LT(r.begin, r.end);
        ASSERT_LE(r.depth, max_depth);
        next = r.end;
        ASSERT_TRUE(r.end - r.begin <= grain || r.depth == max_depth);
        // All voxels of a range below one node at r.depth, and none of its neighbours.
        const unsigned shift = 3 * (kTreeDepth - r.depth) + 1;
        const uint64_t prefix = r.depth == 0 ? 0 : sorted[r.begin] >> shift;
        for (size_t i = r.begin; i < r.end; ++i) ASSERT_EQ(r.depth == 0 ? 0 : sorted[i] >> shift, prefix);
        if (r.depth > 0 && r.begin > 0) {
          ASSERT_NE(sorted[r.begin - 1] >> shift, prefix);
        }
        if (r.depth > 0 && r.end < sorted.size()) {
          ASSERT_NE(sorted[r.end] >> shift, prefix);
        }
      }
      ASSERT_EQ(next, sorted.size());
    }
  }
}

}  // namespace
}  // namespace ort
