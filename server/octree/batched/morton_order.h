// Morton (Z-order) codes of OcTree keys (voxel_buckets.h orders a scan's list by them).
//
// The code interleaves the key bits so that its 3-bit groups, read from the top, are exactly
// the child indices OctoMap takes on the way from the root to the voxel (computeChildIdx: x is
// bit 0, y bit 1, z bit 2). Sorted codes therefore list the voxels in depth-first order of the
// octree, each subtree's voxels contiguous, and two consecutive voxels share the root path
// down to the depth their codes first differ at.
#pragma once

#include <array>
#include <cstdint>

#include "core/voxel_update.h"

namespace ort {

constexpr unsigned kTreeDepth = 16;  // OcTree's depth: 16-bit keys

namespace detail {
// Bit i of the byte moved to bit 3i, for every byte: 1 KiB that stays in L1. Two lookups
// per coordinate replace five shift-and-mask steps; this runs for every voxel of every scan.
constexpr std::array<uint32_t, 256> make_spread_table() {
  std::array<uint32_t, 256> t{};
  for (uint32_t b = 0; b < 256; ++b)
    for (unsigned i = 0; i < 8; ++i) t[b] |= ((b >> i) & 1u) << (3 * i);
  return t;
}
inline constexpr std::array<uint32_t, 256> kSpreadByte = make_spread_table();

// Spreads the 16 bits of v to every third bit (bit i -> bit 3i).
inline uint64_t spread_bits(uint16_t v) {
  return uint64_t{kSpreadByte[v & 0xffu]} | (uint64_t{kSpreadByte[v >> 8]} << 24);
}
}  // namespace detail

// 48-bit Morton code of a key (inline: it is computed for every voxel of every scan).
inline uint64_t morton_code(uint16_t x, uint16_t y, uint16_t z) {
  return detail::spread_bits(x) | (detail::spread_bits(y) << 1) | (detail::spread_bits(z) << 2);
}
// The same for coordinates below 256 (a key's low bits inside a node of at most 256 keys a
// side): one table lookup per axis.
inline uint64_t morton_code_low_byte(uint8_t x, uint8_t y, uint8_t z) {
  const auto& spread = detail::kSpreadByte;
  return uint64_t{spread[x]} | (uint64_t{spread[y]} << 1) | (uint64_t{spread[z]} << 2);
}
// The key back from a Morton code.
void morton_decode(uint64_t code, uint16_t& x, uint16_t& y, uint16_t& z);

// One voxel of a sorted batch: its Morton code shifted up by one, occupied in bit 0. Keys are
// unique in a scan's list, so the state bit never changes the order.
using SortedVoxel = uint64_t;

inline SortedVoxel make_sorted_voxel(const VoxelUpdate& u) {
  return (morton_code(u.x, u.y, u.z) << 1) | (u.occupied() ? 1u : 0u);
}
inline bool sorted_voxel_occupied(SortedVoxel v) { return (v & 1u) != 0; }
inline uint64_t sorted_voxel_code(SortedVoxel v) { return v >> 1; }

// Child index (0..7) a voxel takes below the node at `depth` (0 = root).
inline unsigned child_index_at(SortedVoxel v, unsigned depth) {
  return static_cast<unsigned>(v >> (3 * (kTreeDepth - 1 - depth) + 1)) & 7u;
}

// Deepest depth whose node lies on both voxels' root paths: the node where the paths part;
// kTreeDepth for the same key (a scan's list should never repeat a key, but if it does the
// key is updated twice, as OctoMap's loop would).
inline unsigned shared_path_depth(SortedVoxel a, SortedVoxel b) {
  const uint64_t diff = (a ^ b) >> 1;
  if (diff == 0) return kTreeDepth;
  const unsigned top_bit = 63u - static_cast<unsigned>(__builtin_clzll(diff));
  return kTreeDepth - 1 - top_bit / 3;
}

}  // namespace ort
