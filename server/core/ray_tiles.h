// Window planning that follows the rays' paths instead of their bounding box (issue 13).
//
// The back ends with a grid (cpu-grid, vulkan, rt) lay the scan's key box over their grid
// as windows and walk every ray once per window. For a scan whose few rays fan out over
// kilometres, the key box is mostly empty space: one valid 50-point scan with points 3 km
// away made ~800,000 windows of 50 full walks each and wedged the server. Here the key
// space is cut into cubic tiles and each ray is given only the tiles its segment passes
// (conservatively: the key box of every piece of at most half a tile, widened by the
// DDA's overstep margin). A tile is then shot as its own batch (its rays only, its box as
// the ray space), so the cost grows with the tiles the rays cross, not with the volume of
// their box. The back ends mark only voxels inside a window, and a voxel's state depends
// only on the rays through it, which all belong to its tile: the union of the tiles'
// voxels (each cut to its tile) is exactly the scan's voxel list.
#pragma once

#include <cstdint>
#include <vector>

#include "core/ray_batch.h"

namespace ort {

// OctoMap 1.9.7's KeyRay holds 100,000 keys and computeRayKeys writes past it without a
// check in release builds (an assert in debug builds): a ray whose walk is longer cannot be
// processed the way OctoMap does, and the engine refuses it (see prepare_scan's too_long).
inline constexpr uint64_t kMaxRayWalkKeys = 100'000 - 2;

// Keys the walk of `e` from the batch's origin visits at most: |dx| + |dy| + |dz| + 1.
uint64_t ray_walk_keys(const RayBatch& batch, const RayEnd& e);

// ray_walk_keys over every ray of the batch: the sum (the scan's work) and the longest walk.
struct WalkKeyTotals {
  uint64_t sum = 0, longest = 0;
};
// Four rays at a time where the CPU has AVX2 (the same double division, addition, clamp and
// truncation in lanes, so the same counts), else ray by ray. `simd` false: ray by ray.
WalkKeyTotals batch_walk_keys(const RayBatch& batch, bool simd = true);

struct RayTile {
  KeyBox box;                  // the tile, cut to the scan's widened key box
  std::vector<uint32_t> rays;  // indices into RayBatch::ends, ascending
};

struct TilePlan {
  std::vector<RayTile> tiles;
  uint64_t walk_keys = 0;  // sum over tiles of the walks of their rays: the scan's cost
};

// Tiles of `side` keys a side (aligned to multiples of side), each with the rays that may
// mark a voxel in it. Only tiles some ray meets are listed.
TilePlan plan_ray_tiles(const RayBatch& batch, int side = 512, int margin = 2);

// The cost plan_ray_tiles would report, without building the tiles (no allocation per ray):
// used to refuse a scan before any work is done.
uint64_t tiled_walk_keys(const RayBatch& batch, int side = 512, int margin = 2);

}  // namespace ort
