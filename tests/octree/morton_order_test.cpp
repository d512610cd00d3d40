// Morton codes follow OctoMap's own child order.
#include <random>

#include <gtest/gtest.h>
#include <octomap/OcTreeKey.h>

#include "octree/batched/morton_order.h"

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

// The code by its definition, bit by bit: key bit i of x, y, z at code bits 3i, 3i+1, 3i+2.
uint64_t morton_by_bits(uint16_t x, uint16_t y, uint16_t z) {
  uint64_t code = 0;
  for (unsigned i = 0; i < 16; ++i)
    code |= (uint64_t{(x >> i) & 1u} << (3 * i)) | (uint64_t{(y >> i) & 1u} << (3 * i + 1)) |
            (uint64_t{(z >> i) & 1u} << (3 * i + 2));
  return code;
}

TEST(MortonOrder, EveryCoordinateOfEveryAxisIsInterleavedBitByBit) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> key(0, 65535);
  for (uint32_t v = 0; v < 65536; ++v) {
    const auto c = static_cast<uint16_t>(v), o1 = static_cast<uint16_t>(key(rng)), o2 = static_cast<uint16_t>(key(rng));
    ASSERT_EQ(morton_code(c, o1, o2), morton_by_bits(c, o1, o2)) << "x " << v;
    ASSERT_EQ(morton_code(o1, c, o2), morton_by_bits(o1, c, o2)) << "y " << v;
    ASSERT_EQ(morton_code(o1, o2, c), morton_by_bits(o1, o2, c)) << "z " << v;
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

}  // namespace
}  // namespace ort
