// How big the compute back end's persistent ray space is: the 2-bit grid, its touched-word
// list and the voxel output, all decided once at start-up.
#pragma once

#include <cstdint>

namespace ort::gpu {

struct RaySpaceSizing {
  uint64_t grid_words = 0;     // 32-bit words of 2-bit states (16 voxels each); also the
                               // touched list's capacity, since a word is listed once a window
  uint64_t output_voxels = 0;  // capacity of the voxel output buffer (8 bytes a voxel)
  uint32_t chunk_words = 0;    // touched words one compact pass covers: 16 * chunk <= output
};

// The automatic grid budget in bytes: the largest storage buffer the device allows, at most
// an eighth of its device-local memory and at most 1 GiB (so voxel indices fit in 32 bits).
uint64_t auto_grid_budget(uint64_t max_storage_buffer_range, uint64_t device_local_bytes);

// With a max range (>= 0) the grid is a cube of side 2 * (ceil(max_range / res) + 3) + 1
// voxels: any ray space of one scan then fits in one window. Either way it is capped by
// `budget_bytes` (and by max_buffer_bytes); without a max range it is the budget. The output
// holds every voxel of a full grid up to 16M voxels (128 MiB), else 4 voxels a word, bounded
// by max_buffer_bytes and 512 MiB; larger scans are compacted in several chunks.
// `output_voxels` > 0 replaces the automatic output capacity (tests use a small one to make
// compaction run in chunks).
RaySpaceSizing size_ray_space(double max_range, double resolution, uint64_t budget_bytes, uint64_t max_buffer_bytes,
                              uint32_t max_dispatch_groups, uint64_t output_voxels = 0);

// A grid of `words` with the output and compaction chunks size_ray_space gives it.
RaySpaceSizing ray_space_of_words(uint64_t words, uint64_t max_buffer_bytes, uint32_t max_dispatch_groups,
                                  uint64_t output_voxels = 0);

// Without a max range and without a grid budget given, the grid is sized from the scans: it
// starts at this many words (4 MiB, 16M voxels) and grows (GpuRaySpace::fit) as a scan's ray
// space needs, up to the automatic budget.
inline constexpr uint64_t kStartGridWords = uint64_t(1) << 20;

}  // namespace ort::gpu
