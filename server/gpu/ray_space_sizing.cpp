#include "gpu/ray_space_sizing.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "gpu/shader_interface.h"

namespace ort::gpu {

uint64_t auto_grid_budget(uint64_t max_storage_buffer_range, uint64_t device_local_bytes) {
  return std::min({max_storage_buffer_range, device_local_bytes / 8, uint64_t(1) << 30});
}

RaySpaceSizing size_ray_space(double max_range, double resolution, uint64_t budget_bytes, uint64_t max_buffer_bytes,
                              uint32_t max_dispatch_groups, uint64_t output_voxels) {
  // Voxel indices inside a window are uint32 in the shaders: at most 2^28 words.
  uint64_t words = std::min({budget_bytes, max_buffer_bytes, uint64_t(1) << 30}) / 4;
  if (max_range >= 0.0) {
    // The cut end of a ray can land one voxel beyond max_range / res, and the window is
    // widened by 2 voxels for the walk's overstep: 3 voxels of margin a side.
    const double half = std::ceil(max_range / resolution) + 3.0;
    const double side = 2.0 * half + 1.0;
    const double voxels = side * side * side;
    if (voxels < double(words) * kVoxelsPerWord) words = (uint64_t(voxels) + kVoxelsPerWord - 1) / kVoxelsPerWord;
  }
  return ray_space_of_words(words, max_buffer_bytes, max_dispatch_groups, output_voxels);
}

RaySpaceSizing ray_space_of_words(uint64_t words, uint64_t max_buffer_bytes, uint32_t max_dispatch_groups,
                                  uint64_t output_voxels) {
  RaySpaceSizing s;
  if (words == 0) throw std::invalid_argument("the ray-space grid budget holds no voxels");
  s.grid_words = words;
  const uint64_t output_cap = std::min<uint64_t>(max_buffer_bytes, uint64_t(512) << 20) / 8;
  s.output_voxels = std::min({words * kVoxelsPerWord, std::max<uint64_t>(uint64_t(16) << 20, words * 4), output_cap});
  if (output_voxels) s.output_voxels = std::min(output_voxels, output_cap);
  const uint64_t chunk =
      std::min<uint64_t>(s.output_voxels / kVoxelsPerWord, uint64_t(max_dispatch_groups) * kCompactGroup);
  s.chunk_words = uint32_t(std::max<uint64_t>(chunk, 1));
  s.output_voxels = std::max<uint64_t>(s.output_voxels, uint64_t(s.chunk_words) * kVoxelsPerWord);
  return s;
}

}  // namespace ort::gpu
