// Planning the key-aligned windows of the shared ray space for one scan.
//
// A back end keeps one grid of 2-bit voxel states for its whole life. Per scan, the scan's
// ray space (the key box of its origin and ends, widened by a small margin because a DDA can
// step one voxel past its end key) is laid over the grid as a window; a ray space with more
// voxels than the grid holds is split into several windows, never dropped.
#pragma once

#include <cstdint>
#include <vector>

#include "core/ray_batch.h"

namespace ort {

// Voxel index of key k inside window w (x fastest), or -1 when k lies outside.
inline int64_t window_index(const KeyBox& w, int x, int y, int z) {
  if (x < w.lo[0] || x > w.hi[0] || y < w.lo[1] || y > w.hi[1] || z < w.lo[2] || z > w.hi[2]) return -1;
  const int64_t nx = w.hi[0] - w.lo[0] + 1, ny = w.hi[1] - w.lo[1] + 1;
  return (x - w.lo[0]) + nx * ((y - w.lo[1]) + ny * int64_t(z - w.lo[2]));
}

// Widens `space` by `margin` voxels a side (a DDA may step one voxel past its end key),
// clamps it to [0, 65535] and cuts it into disjoint windows of at most `capacity_voxels`
// voxels that cover the widened box exactly. Used by the cpu-grid and vulkan back ends.
std::vector<KeyBox> plan_windows(const KeyBox& space, uint64_t capacity_voxels, int margin = 2);

}  // namespace ort
