// The `cpu-grid` back end: the paper's shared ray space, on the CPU. Worker threads walk the
// rays (OctoMap's exact DDA, or the exact closed-box traversal) into a persistent grid of
// 2-bit voxel states with atomic OR, list the words they touch first, and compact those words
// into the voxel list, clearing them as they go. It replaces OctoMap's hash-set inserts (one
// per voxel visit) with a bit set in a dense word, for machines without a GPU.
#pragma once

#include <memory>

#include "core/ray_backend.h"

namespace ort {

struct CpuGridOptions {
  double resolution = 0.1;
  uint64_t grid_budget_bytes = 256ull << 20;  // the persistent grid; 0 = 256 MiB
  unsigned threads = 0;                       // 0 = hardware threads
  bool simd = true;                           // AVX2 ray walk where the CPU has it (false: scalar only)
  // The walk's threads other than the caller run at the lowest priority (nice 19): they take
  // the cores another stage leaves idle and give way when it runs (BackendOptions::helpers_yield).
  bool helpers_yield = false;
  // A window whose walk touched at most this many grid words is compacted on the caller's
  // thread alone (a thread started per window and words last written on another core cost
  // more than they save there); larger ones on all the walk's threads.
  uint64_t compact_alone_up_to_words = 1u << 20;
};

std::unique_ptr<RayBackend> make_cpu_grid_backend(const CpuGridOptions& opts);

}  // namespace ort
