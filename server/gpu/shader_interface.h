// Host-side mirrors of the compute shaders' push constants and counters
// (shaders/ray_space.glsl, shaders/compact_touched.comp). Keep the two in step.
#pragma once

#include <cstddef>
#include <cstdint>

namespace ort::gpu {

inline constexpr uint32_t kShootGroup = 64;     // local_size_x of shoot_*.comp
inline constexpr uint32_t kCompactGroup = 256;  // local_size_x of compact_touched.comp
inline constexpr uint32_t kVoxelsPerWord = 16;  // 2-bit states in a uint32
inline constexpr uint32_t kPrepareGroup = 64;   // local_size_x of prepare_rays.comp

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

// prepare_rays.comp's push constants: the pose, the origin and the max-range rule of a scan.
struct PreparePush {
  double resolution_factor;
  float rot[4];  // u, x, y, z
  float trans[3];
  uint32_t point_count;
  float origin[3];
  uint32_t point_base;
  float norm_sq_limit;
  float max_range_f;
  uint32_t has_max_range;
  float zero;
  float tiny_coordinate;  // prepare_scan.h's kTinyCoordinate and kMinRayLength
  float min_ray_length;
};
static_assert(sizeof(PreparePush) == 80);
static_assert(offsetof(PreparePush, rot) == 8 && offsetof(PreparePush, point_count) == 36 &&
              offsetof(PreparePush, point_base) == 52 && offsetof(PreparePush, zero) == 68);

// prepare_rays.comp's result buffer: the key box of the kept ends and what was dropped or cut.
struct PrepareCounts {
  uint32_t key_lo[3];  // ~0u: no end kept
  uint32_t key_hi[3];
  uint32_t nonfinite;
  uint32_t out_of_range;
  uint32_t cut_at_max_range;
  uint32_t degenerate;    // prepare_scan.h's degenerate_ray
  uint32_t read_as_zero;  // points with a coordinate read as 0 (prepare_scan.h's kTinyCoordinate)
};
static_assert(sizeof(PrepareCounts) == 44);

// The Counters buffer; its first three words are the compact pass's VkDispatchIndirectCommand.
struct Counters {
  uint32_t dispatch_x, dispatch_y, dispatch_z;
  uint32_t touched_count;
  uint32_t emitted_count;
  uint32_t walk_overruns;    // rays stopped by the shaders' step guard: must stay 0
  uint32_t words_compacted;  // touched words the compact passes read and cleared
};
static_assert(sizeof(Counters) == 28);
inline constexpr size_t kEmittedOffset = offsetof(Counters, emitted_count);

}  // namespace ort::gpu
