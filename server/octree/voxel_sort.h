// Sorting one scan's voxel list into Morton order, on the octree stage's threads.
//
// The codes of a scan differ only in their low bits (a scan covers a small part of the
// 2^16 keys per axis), so the sort looks at the bits that vary only: one parallel
// most-significant-digit pass on the top 11 of them scatters the list into up to 2048
// buckets, and each bucket, small enough to stay in cache, is finished by a least-
// significant-digit radix sort on the rest, buckets spread over the threads.
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
