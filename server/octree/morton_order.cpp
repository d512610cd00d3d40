#include "octree/morton_order.h"

#include <algorithm>
#include <array>

namespace ort {
namespace {

// Spreads the 16 bits of v to every third bit (bit i -> bit 3i).
uint64_t spread_bits(uint64_t v) {
  v &= 0xffffu;
  v = (v | (v << 16)) & 0x0000ff0000ffull;
  v = (v | (v << 8)) & 0x00f00f00f00full;
  v = (v | (v << 4)) & 0x0c30c30c30c3ull;
  v = (v | (v << 2)) & 0x249249249249ull;
  return v;
}

uint16_t compact_bits(uint64_t v) {
  v &= 0x249249249249ull;
  v = (v | (v >> 2)) & 0x0c30c30c30c3ull;
  v = (v | (v >> 4)) & 0x00f00f00f00full;
  v = (v | (v >> 8)) & 0x0000ff0000ffull;
  v = (v | (v >> 16)) & 0xffffu;
  return static_cast<uint16_t>(v);
}

// Sorted voxels use 49 bits: seven 8-bit digits.
constexpr unsigned kDigits = 7;
constexpr unsigned kBuckets = 256;

void radix_sort(std::vector<SortedVoxel>& data, std::vector<SortedVoxel>& scratch) {
  const size_t n = data.size();
  // All digit histograms in one read of the data.
  std::vector<std::array<size_t, kBuckets>> hist(kDigits);
  for (auto& h : hist) h.fill(0);
  for (SortedVoxel v : data)
    for (unsigned d = 0; d < kDigits; ++d) ++hist[d][(v >> (8 * d)) & 0xffu];
  scratch.resize(n);
  for (unsigned d = 0; d < kDigits; ++d) {
    auto& h = hist[d];
    // A digit that all voxels share leaves the order as it is: scans cover a small part of
    // the key range, so several of the high digits usually are skipped.
    if (std::any_of(h.begin(), h.end(), [n](size_t c) { return c == n; })) continue;
    size_t offset = 0;
    for (size_t& c : h) {
      const size_t count = c;
      c = offset;
      offset += count;
    }
    for (SortedVoxel v : data) scratch[h[(v >> (8 * d)) & 0xffu]++] = v;
    data.swap(scratch);
  }
}

}  // namespace

uint64_t morton_code(uint16_t x, uint16_t y, uint16_t z) {
  return spread_bits(x) | (spread_bits(y) << 1) | (spread_bits(z) << 2);
}

void morton_decode(uint64_t code, uint16_t& x, uint16_t& y, uint16_t& z) {
  x = compact_bits(code);
  y = compact_bits(code >> 1);
  z = compact_bits(code >> 2);
}

void sort_voxels(std::span<const VoxelUpdate> updates, std::vector<SortedVoxel>& out,
                 std::vector<SortedVoxel>& scratch, SortMethod method) {
  out.resize(updates.size());
  for (size_t i = 0; i < updates.size(); ++i) out[i] = make_sorted_voxel(updates[i]);
  if (method == SortMethod::kStd)
    std::sort(out.begin(), out.end());
  else
    radix_sort(out, scratch);
}

}  // namespace ort
