// Setting 2-bit voxel states in the cpu-grid's words, shared by its scalar and SIMD walks.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "core/voxel_update.h"

namespace ort {

// Sets 2-bit states in the grid and lists each word the first time it becomes non-zero.
// `shared`: other threads mark the same grid (atomic OR); otherwise plain loads and stores.
struct GridMarker {
  uint32_t* grid;
  std::vector<uint32_t>& touched;
  bool shared;

  [[gnu::always_inline]] void mark(uint32_t idx, uint32_t bits) {
    const uint32_t word = idx / 16u;  // 16 voxels of 2 bits a word
    const uint32_t mask = bits << (2 * (idx % 16u));
    uint32_t& cell = grid[word];
    // Most visits near the sensor find their bit set already: read before the atomic.
    const uint32_t old = std::atomic_ref<uint32_t>(cell).load(std::memory_order_relaxed);
    if ((old & mask) == mask) return;
    if (shared) {
      if (std::atomic_ref<uint32_t>(cell).fetch_or(mask, std::memory_order_relaxed) == 0) touched.push_back(word);
    } else {
      std::atomic_ref<uint32_t>(cell).store(old | mask, std::memory_order_relaxed);
      if (old == 0) touched.push_back(word);
    }
  }

  // mark() for each of n indices; without a branch on the grid's bits where only this thread
  // writes the grid (the caller found most of them unset: a test would mispredict).
  void mark_all(const uint32_t* idx, int n, uint32_t bits) {
    if (shared) {
      for (int i = 0; i < n; ++i) mark(idx[i], bits);
      return;
    }
    size_t count = touched.size();
    touched.resize(count + size_t(n));
    uint32_t* listed = touched.data();
    for (int i = 0; i < n; ++i) {
      const uint32_t word = idx[i] / 16u;
      const uint32_t old = grid[word];
      grid[word] = old | bits << (2 * (idx[i] % 16u));
      listed[count] = word;
      count += old == 0;
    }
    touched.resize(count);
  }
};

}  // namespace ort
