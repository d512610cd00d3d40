// bucket_voxels cuts a list into the subtrees of one depth, in Morton order, and sorting
// each bucket gives exactly the Morton sort of the whole list, keeping the list's order of a
// repeated key's updates; with and without threads, for dense, sparse and origin-crossing
// lists.
#include <algorithm>
#include <map>
#include <random>
#include <tuple>

#include <gtest/gtest.h>
#include <octomap/OcTreeKey.h>

#include "octree/batched/voxel_buckets.h"

namespace ort {
namespace {

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

// Checks the buckets' shape and returns their concatenation after each was sorted.
std::vector<SortedVoxel> check_and_sort(VoxelBuckets& b, size_t n, const BucketOptions& opts) {
  std::vector<SortedVoxel> all;
  EXPECT_EQ(b.voxels.size(), n);
  if (n == 0) return all;
  EXPECT_GE(b.depth, 1u);
  EXPECT_LE(b.depth, kTreeDepth - std::max(1u, opts.min_shift));
  EXPECT_EQ(b.begin.front(), 0u);
  EXPECT_EQ(b.begin.back(), n);
  const unsigned shift = 3 * (kTreeDepth - b.depth) + 1;
  std::vector<SortedVoxel> tmp;
  for (size_t k = 0; k < b.count(); ++k) {
    const std::span<SortedVoxel> bucket = b.bucket(k);
    EXPECT_FALSE(bucket.empty());
    const uint64_t node = bucket.front() >> shift;
    for (SortedVoxel v : bucket) EXPECT_EQ(v >> shift, node) << "bucket " << k << " spans two nodes";
    if (k > 0) {
      EXPECT_LT(b.bucket(k - 1).front() >> shift, node) << "buckets out of Morton order";
    }
    sort_bucket(bucket, tmp, 3 * (kTreeDepth - b.depth));  // as the batched update sorts them
    all.insert(all.end(), bucket.begin(), bucket.end());
  }
  return all;
}

TEST(VoxelBuckets, SortedBucketsAreTheMortonSortOfTheList) {
  std::mt19937 rng(3);
  WorkerPool pool(3);
  BucketOptions deep;
  deep.voxels_per_cell = 1;
  deep.max_cells = 1 << 20;
  deep.min_shift = 1;
  BucketOptions coarse;
  coarse.min_shift = 15;
  for (auto [n, lo, hi] : {std::tuple{0, 0, 1},
                           {1, 0, 65535},
                           {1000, 32700, 32800},
                           {200000, 0, 65535},
                           {100000, 32000, 33000},
                           {60000, 32760, 32800},
                           {50000, 0, 40},
                           {40000, 65500, 65535}}) {
    const VoxelList list = random_unique_list(rng, n, lo, hi);
    std::vector<SortedVoxel> expected;
    for (const VoxelUpdate& u : list) expected.push_back(make_sorted_voxel(u));
    std::sort(expected.begin(), expected.end());
    for (const BucketOptions& opts : {BucketOptions{}, deep, coarse}) {
      VoxelBuckets one, pooled;
      BucketScratch scratch;
      bucket_voxels(list, opts, nullptr, one, scratch);
      bucket_voxels(list, opts, &pool, pooled, scratch);
      EXPECT_EQ(one.voxels, pooled.voxels) << "threads changed the order inside a bucket";
      EXPECT_EQ(one.begin, pooled.begin);
      EXPECT_LE(one.count(), std::max<size_t>(64, opts.max_cells));
      ASSERT_EQ(check_and_sort(one, list.size(), opts), expected)
          << n << " voxels in [" << lo << "," << hi << "], min_shift " << opts.min_shift;
      ASSERT_EQ(check_and_sort(pooled, list.size(), opts), expected) << "3 threads";
    }
  }
}

// The storage a scan's buckets leave behind is reused, unwritten, by the next scan's
// (UninitializedAllocator): lists longer and shorter than before give what fresh buckets give.
TEST(VoxelBuckets, ReusedBucketsGiveWhatFreshOnesGive) {
  std::mt19937 rng(11);
  WorkerPool pool(3);
  VoxelBuckets reused;
  BucketScratch reused_scratch;
  for (size_t n : {1000u, 200000u, 50000u, 0u, 300000u, 10u, 250000u}) {
    const VoxelList list = random_unique_list(rng, n, 32000, 33000);
    VoxelBuckets fresh;
    BucketScratch scratch;
    bucket_voxels(list, BucketOptions{}, &pool, fresh, scratch);
    bucket_voxels(list, BucketOptions{}, &pool, reused, reused_scratch);
    ASSERT_EQ(reused.voxels, fresh.voxels) << n << " voxels";
    ASSERT_EQ(reused.begin, fresh.begin) << n << " voxels";
    ASSERT_EQ(reused.depth, fresh.depth) << n << " voxels";
  }
}

// sort_bucket alone, on buckets of nodes of 2^3 .. 2^6 voxels a side (the slot-per-key path
// up to 4096 voxels, radix sorts above), full and sparse, with and without one repeated key
// (which must keep the list's order of its two updates): always std::stable_sort's result.
TEST(VoxelBuckets, SortBucketIsTheStableMortonSort) {
  std::mt19937 rng(21);
  std::vector<SortedVoxel> tmp;
  for (unsigned side_bits : {3u, 4u, 5u, 6u}) {
    const int side = 1 << side_bits;
    for (size_t n : {size_t{33}, size_t{200}, size_t{1} << (3 * std::min(side_bits, 4u))}) {
      for (bool repeat : {false, true}) {
        // Unique keys inside one node at (32768 - side .. 32768) on each axis.
        std::vector<octomap::OcTreeKey> all;
        for (int x = 0; x < side; ++x)
          for (int y = 0; y < side; ++y)
            for (int z = 0; z < side; ++z) all.emplace_back(32768 - side + x, 32768 - side + y, 32768 - side + z);
        std::shuffle(all.begin(), all.end(), rng);
        std::vector<SortedVoxel> bucket;
        for (size_t i = 0; i < n && i < all.size(); ++i)
          bucket.push_back(make_sorted_voxel(make_update(all[i], rng() % 2)));
        if (repeat) {
          // The first key again, in the other state, somewhere later.
          const SortedVoxel again = bucket.front() ^ 1u;
          bucket.insert(bucket.begin() + static_cast<long>(1 + rng() % (bucket.size() - 1)), again);
        }
        std::vector<SortedVoxel> expected = bucket;
        std::stable_sort(expected.begin(), expected.end(),
                         [](SortedVoxel a, SortedVoxel b) { return (a >> 1) < (b >> 1); });
        std::vector<SortedVoxel> told = bucket;  // sorted knowing its node's size, as bucket_voxels' buckets are
        sort_bucket(bucket, tmp);
        ASSERT_EQ(bucket, expected) << "side " << side << ", " << n << " voxels, repeat " << repeat;
        sort_bucket(told, tmp, 3 * side_bits);
        ASSERT_EQ(told, expected) << "side " << side << ", " << n << " voxels, repeat " << repeat
                                  << ", node bits given";
      }
    }
  }
}

TEST(VoxelBuckets, ARepeatedKeyKeepsTheListsOrder) {
  std::mt19937 rng(8);
  WorkerPool pool(2), five(5);  // the list in 6 and 9 chunks, taken by whichever thread comes
  // 40,000 updates of 3,000 keys: each key 13 times on average, in both states.
  std::uniform_int_distribution<int> key(32750, 32790);
  std::vector<octomap::OcTreeKey> keys;
  for (int i = 0; i < 3000; ++i) keys.emplace_back(key(rng), key(rng), key(rng));
  VoxelList list;
  std::map<uint64_t, std::vector<bool>> states_in_list_order;
  for (int i = 0; i < 40000; ++i) {
    const octomap::OcTreeKey& k = keys[rng() % keys.size()];
    const bool occupied = rng() % 2 == 0;
    list.push_back(make_update(k, occupied));
    states_in_list_order[morton_code(k[0], k[1], k[2])].push_back(occupied);
  }
  for (WorkerPool* p : {static_cast<WorkerPool*>(nullptr), &pool, &five}) {
    VoxelBuckets b;
    BucketScratch scratch;
    bucket_voxels(list, BucketOptions{}, p, b, scratch);
    std::map<uint64_t, std::vector<bool>> seen;
    std::vector<SortedVoxel> tmp;
    uint64_t last = 0;
    for (size_t k = 0; k < b.count(); ++k) {
      sort_bucket(b.bucket(k), tmp);
      for (SortedVoxel v : b.bucket(k)) {
        ASSERT_GE(sorted_voxel_code(v), last);
        last = sorted_voxel_code(v);
        seen[sorted_voxel_code(v)].push_back(sorted_voxel_occupied(v));
      }
    }
    EXPECT_EQ(seen, states_in_list_order);
  }
}

}  // namespace
}  // namespace ort
