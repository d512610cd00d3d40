// Sorting one scan's voxel list into Morton order, on the octree stage's threads.
//
// The sort looks only at the bits that vary: one parallel most-significant-digit pass on
// the top 11 of them scatters the list into up to 2048 buckets; the buckets, spread over the
// threads, are split the same way on their own varying bits until a part fits in cache,
// which least-significant-digit radix passes finish.
#pragma once

#include <span>
#include <vector>

#include "engine/voxel_update.h"
#include "octree/morton_order.h"
#include "octree/worker_pool.h"

namespace ort {

enum class SortMethod {
  kRadix,  // the radix sort described above
  kStd,    // std::sort on one thread, for comparison (tools/octree_bench)
};

// Codes of `updates` (make_sorted_voxel), ascending, in `out`. `scratch` is reused storage.
// With a pool the work is spread over its workers (pool->run is called; not from inside
// another run of the same pool).
void sort_voxels(std::span<const VoxelUpdate> updates, std::vector<SortedVoxel>& out,
                 std::vector<SortedVoxel>& scratch, SortMethod method = SortMethod::kRadix,
                 WorkerPool* pool = nullptr);

}  // namespace ort
