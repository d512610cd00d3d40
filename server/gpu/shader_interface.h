// Host-side mirrors of the compute shaders' push constants and counters
// (shaders/ray_space.glsl, shaders/compact_touched.comp). Keep the two in step.
#pragma once

#include <cstddef>
#include <cstdint>

namespace ort::gpu {

inline constexpr uint32_t kShootGroup = 64;     // local_size_x of shoot_*.comp
inline constexpr uint32_t kCompactGroup = 256;  // local_size_x of compact_touched.comp
inline constexpr uint32_t kVoxelsPerWord = 16;  // 2-bit states in a uint32

struct ShootPush {
  double resolution;
  double resolution_factor;
  float origin[3];
  uint32_t ray_count;
  int32_t win_lo[3];
  uint32_t first_chunk_words;
  uint32_t win_n[3];
  uint32_t ray_base;  // first ray of this dispatch (dispatches are split at 65535 groups)
  int32_t origin_key[3];
  uint32_t pad1;
};
static_assert(sizeof(ShootPush) == 80);
static_assert(offsetof(ShootPush, origin) == 16 && offsetof(ShootPush, win_lo) == 32 &&
              offsetof(ShootPush, win_n) == 48 && offsetof(ShootPush, origin_key) == 64);

struct CompactPush {
  int32_t win_lo[3];
  uint32_t chunk_begin;
  uint32_t win_n[3];
  uint32_t chunk_words;
};
static_assert(sizeof(CompactPush) == 32);

// The Counters buffer; its first three words are the compact pass's VkDispatchIndirectCommand.
struct Counters {
  uint32_t dispatch_x, dispatch_y, dispatch_z;
  uint32_t touched_count;
  uint32_t emitted_count;
  uint32_t walk_overruns;    // rays stopped by the shaders' step guard: must stay 0
  uint32_t words_compacted; // touched words the compact passes read and cleared
};
static_assert(sizeof(Counters) == 28);
inline constexpr size_t kEmittedOffset = offsetof(Counters, emitted_count);

}  // namespace ort::gpu
