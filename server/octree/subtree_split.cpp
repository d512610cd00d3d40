#include "octree/subtree_split.h"

#include <algorithm>

namespace ort {
namespace {

void split_range(std::span<const SortedVoxel> voxels, size_t begin, size_t end, unsigned depth, size_t grain,
                 unsigned max_depth, std::vector<SubtreeRange>& out) {
  if (end - begin <= grain || depth >= max_depth) {
    out.push_back(SubtreeRange{begin, end, depth});
    return;
  }
  // The voxels of one node share the path above it, so their child index at this depth
  // rises through the range: each child's voxels are one run.
  size_t child_begin = begin;
  while (child_begin < end) {
    const unsigned child = child_index_at(voxels[child_begin], depth);
    const auto child_end_it = std::partition_point(
        voxels.begin() + static_cast<std::ptrdiff_t>(child_begin), voxels.begin() + static_cast<std::ptrdiff_t>(end),
        [&](SortedVoxel v) { return child_index_at(v, depth) == child; });
    const size_t child_end = static_cast<size_t>(child_end_it - voxels.begin());
    split_range(voxels, child_begin, child_end, depth + 1, grain, max_depth, out);
    child_begin = child_end;
  }
}

}  // namespace

std::vector<SubtreeRange> split_into_subtrees(std::span<const SortedVoxel> voxels, size_t grain,
                                              unsigned max_depth) {
  std::vector<SubtreeRange> out;
  if (voxels.empty()) return out;
  split_range(voxels, 0, voxels.size(), 0, std::max<size_t>(grain, 1), std::min(max_depth, kTreeDepth), out);
  return out;
}

}  // namespace ort
