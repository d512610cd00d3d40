// One scan's voxel list cut into subtrees for the octree stage's threads, without sorting the
// whole list: every voxel goes into the bucket of its node at one depth D (its "cell"), the
// buckets in Morton order of their nodes, and each bucket is sorted on its own later, by the
// thread that updates it, while it sits in that thread's cache.
//
// Why not a global Morton sort: a scan around the map origin varies in every key bit
// (0x7fff -> 0x8000), so a sort of whole codes either makes extra passes or splits the list
// into only the 8 octants first; and it is a pass over the whole list that the threads must
// wait for. Here the cells are numbered densely per axis: only node coordinates some voxel
// has count (a rank table per axis), so D can be deep even when the scan's voxels are spread
// over the whole key range, and the three passes (occupied coordinates, counts, scatter) are
// split over the threads with nothing serial but the choice of D and the prefix sums over
// the cells.
#pragma once

#include <cstddef>
#include <memory>
#include <new>
#include <span>
#include <utility>
#include <vector>

#include "core/voxel_update.h"
#include "octree/batched/morton_order.h"
#include "octree/worker_pool.h"

namespace ort {

struct BucketOptions {
  // Cells (nodes at depth D in the box of occupied node coordinates) allowed per voxel of the
  // list: D is the deepest with at most max(64, size / voxels_per_cell) cells. More cells:
  // smaller buckets (better balance, cheaper sorts), more nodes above them to make first.
  unsigned voxels_per_cell = 32;
  size_t max_cells = 65536;
  // Buckets are nodes of at least 2^min_shift voxels a side (D <= 16 - min_shift), and never
  // the root (D >= 1).
  unsigned min_shift = 3;
};

// Allocates like std::allocator but leaves new elements of a trivial type unwritten on
// resize: bucket_voxels writes every one in its scatter pass, on all its threads, so a list
// longer than any before is neither zeroed first nor first touched (page faults) on one thread.
template <class T>
struct UninitializedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;  // default-initialised: no value written
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

struct VoxelBuckets {
  std::vector<SortedVoxel, UninitializedAllocator<SortedVoxel>> voxels;  // grouped by bucket, buckets in Morton order
  std::vector<size_t> begin;                                             // bucket b is voxels[begin[b], begin[b + 1])
  unsigned depth = 0;  // D: every bucket holds the voxels below one node at D

  size_t count() const { return begin.empty() ? 0 : begin.size() - 1; }
  std::span<SortedVoxel> bucket(size_t b) { return {voxels.data() + begin[b], begin[b + 1] - begin[b]}; }
};

// Reused storage of bucket_voxels (per-chunk counts, rank tables).
struct BucketScratch {
  std::vector<uint64_t> occupied;      // [axis][1024 words]: key coordinates that occur, one bit each
  std::vector<uint8_t> seen;           // [axis][65536]: the same as bytes, on one thread
  std::vector<uint32_t> counts;        // [chunk][cell]: voxels, then the chunks' offsets
  std::vector<uint32_t> totals;        // [cell]: voxels
  std::vector<uint32_t> cell_begin;    // [cell]: first index of its bucket (nonempty cells)
  std::vector<SortedVoxel> cell_code;  // [cell]: its node's code bits of every voxel in it (nonempty cells)
  std::vector<uint32_t> cell_of_axis[3];
  std::vector<std::pair<uint64_t, uint32_t>> nonempty;  // (node code, cell)
};

// Buckets `updates` (order within a bucket: the list's order). Keys may repeat.
// With a pool the passes' chunks are shared out over its threads (WorkerPool::run_shared; not
// from inside a run of the same pool).
void bucket_voxels(std::span<const VoxelUpdate> updates, const BucketOptions& opts, WorkerPool* pool, VoxelBuckets& out,
                   BucketScratch& scratch);

// Sorts one bucket into Morton order (stable: a repeated key keeps the list's order of its
// updates). `tmp` is reused storage. `node_bits`: the low code bits the bucket's voxels can
// differ in (3 * (16 - VoxelBuckets::depth) for a bucket of bucket_voxels); where it is small,
// the sort skips the pass that finds the bits that do differ.
void sort_bucket(std::span<SortedVoxel> bucket, std::vector<SortedVoxel>& tmp, unsigned node_bits = 64);

}  // namespace ort
