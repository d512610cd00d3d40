// The rays of one scan, prepared on the CPU for any ray-shooting back end.
//
// Preparation (prepare_scan.h) applies OctoMap's computeUpdate rules with OctoMap's own
// float arithmetic: it drops non-finite points, cuts rays longer than max range (the cut
// end gives free space only) and drops rays whose end lies outside the key range. What is
// left is a plain list of segments that every back end walks the same way.
#pragma once

#include <algorithm>
#include <cstddef>  // OctoMap 1.9.7's OcTreeKey.h needs size_t and uint8_t declared first
#include <cstdint>
#include <vector>

#include <octomap/OcTreeKey.h>
#include <octomap/octomap_types.h>

namespace ort {

// std430-compatible with GLSL `struct RayEnd { vec3 end; uint flags; }` (16 bytes).
struct RayEnd {
  float x, y, z;
  uint32_t flags;  // kRayEndOccupied: the end voxel is a measured hit (not a max-range cut)
};
static_assert(sizeof(RayEnd) == 16);

// kRayEndDropped: a point GPU preparation dropped (non-finite, end outside the key range);
// it keeps its slot so that ray i is point i, and the shooting passes skip it. CPU
// preparation leaves dropped points out instead.
enum RayEndFlags : uint32_t { kRayEndOccupied = 1u, kRayEndDropped = 2u };

// Inclusive box of keys.
struct KeyBox {
  int lo[3] = {0, 0, 0};
  int hi[3] = {-1, -1, -1};
  bool empty() const { return hi[0] < lo[0] || hi[1] < lo[1] || hi[2] < lo[2]; }
  uint64_t voxel_count() const {
    if (empty()) return 0;
    return uint64_t(hi[0] - lo[0] + 1) * uint64_t(hi[1] - lo[1] + 1) * uint64_t(hi[2] - lo[2] + 1);
  }
  void include(const octomap::OcTreeKey& k) {
    if (empty()) {
      for (int i = 0; i < 3; ++i) lo[i] = hi[i] = k[i];
      return;
    }
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min<int>(lo[i], k[i]);
      hi[i] = std::max<int>(hi[i], k[i]);
    }
  }
};

struct RayBatch {
  octomap::point3d origin;  // sensor origin, map frame (float, as OctoMap keeps it)
  octomap::OcTreeKey origin_key;
  std::vector<RayEnd> ends;  // one ray per entry, from origin to end
  KeyBox keys;               // box of the origin key and every end key
  double resolution = 0.1;
  // True where `keys` is known to hold every end key (prepare_scan sets it); false where it may
  // be narrower (a tile's box, MapEngine::shoot_tiled: its rays run on beyond it). Lets the
  // cpu-grid walk know from the box alone that no ray leaves a window (rays_stay_inside).
  bool keys_hold_ends = false;
};

}  // namespace ort
