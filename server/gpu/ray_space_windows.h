// Laying a scan's ray space over the compute back end's persistent grid as key-aligned
// windows. (engine/ray_space.h has a halving planner for the cpu-grid back end; this one cuts
// the fewest windows: each window means one more walk of every ray that meets it.)
#pragma once

#include <cstdint>
#include <vector>

#include "engine/ray_batch.h"

namespace ort::gpu {

// Widens `keys` by `margin` voxels a side (a DDA may step one voxel past its end key),
// clamps to [0, 65535], and cuts the result into boxes of at most `capacity_voxels` voxels:
// slabs across the longest axis, as thick as the capacity allows, recursing when a single
// slab is still too big. The windows are disjoint and cover the widened box exactly.
std::vector<KeyBox> plan_ray_space_windows(const KeyBox& keys, uint64_t capacity_voxels, int margin = 2);

}  // namespace ort::gpu
