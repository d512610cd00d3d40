// The block grid of the `rt` back end: the shape of its BVH (a box of voxels cut into
// blocks of k x k x k) as plain numbers, no Vulkan objects, so that everything here is
// unit-tested on the CPU (tests/gpu/rt_block_grid_test.cpp). Its voxels are the voxels of the
// GPU ray space (gpu/gpu_ray_space.h) that the rt back end shoots into.
//
// Geometry (paper sections IV-B/IV-C): the grid is blocks[0..2] blocks of k x k x k voxels.
// One BLAS holds the k^3 voxel AABBs of one block; the TLAS holds one instance of it per
// block, translated by the block's position. Coordinates inside the grid are in VOXEL units
// with the window's lowest key at 0, so the BVH does not depend on the resolution and float
// keeps ~1e-4 voxel precision over thousands of voxels.
//
// Per scan, the grid is laid over the scan's key box as one or more key-aligned windows
// (lo key = local 0; tile_windows). Rays are moved into a window's frame (to_window_frame),
// traced, and each candidate voxel is decided by the exact double-precision slab test in map
// coordinates, so the float frame only has to find candidates, never to decide.
#pragma once

#include <cstdint>
#include <vector>

#include "core/ray_batch.h"

namespace ort::rt {

constexpr int kTreeMaxVal = 32768;  // OctoMap's key of coordinate 0 at depth 16

// Each voxel's AABB in the BLAS is this much (voxel units) larger on every side than the
// voxel. WHY: Vulkan lets an implementation report AABB hits conservatively but does not
// promise that a ray which only touches a box (along a face, through an edge or a corner)
// is reported, and the rays are moved into the window frame in float. With the margin,
// every box the segment touches is strictly crossed in the float frame (float error there
// is < 1e-3 voxel for windows up to 8192 voxels wide), so the intersection shader is called
// for it; its exact test then throws away the extra neighbours the margin lets in.
constexpr float kAabbMargin = 1.0f / 64.0f;

struct Aabb {  // layout of VkAabbPositionsKHR
  float min[3];
  float max[3];
};
static_assert(sizeof(Aabb) == 24);

struct BlockGrid {
  int block = 4;              // k: voxels along each edge of the BLAS block (2..8)
  int blocks[3] = {1, 1, 1};  // TLAS instances along x, y, z
  int voxels(int axis) const { return blocks[axis] * block; }
  uint64_t instance_count() const { return uint64_t(blocks[0]) * blocks[1] * blocks[2]; }
  uint64_t voxel_count() const { return instance_count() * uint64_t(block) * block * block; }
  uint64_t grid_words() const { return (voxel_count() + 15) / 16; }  // 2-bit states, 16 a word
};

struct BlockGridLimits {
  uint64_t max_voxels = uint64_t(1) << 28;     // 2-bit grid of 64 MiB
  uint64_t max_instances = uint64_t(1) << 22;  // TLAS instance records: 256 MiB at 64 B each
  int max_side = 4096;                         // voxels per axis
};

// Chooses the grid: a box `wanted` voxels per axis (rounded up to whole blocks), shrunk
// along its longest axis until it fits the limits. Throws std::invalid_argument for k
// outside 2..8 or limits that cannot hold one block.
BlockGrid choose_block_grid(int block, const int wanted[3], const BlockGridLimits& limits);
// The wanted voxels per axis for a sensor of this max range (< 0: none, take `fallback`):
// a cube of side 2 * range / resolution plus a margin, as the compute back end sizes its grid.
void wanted_from_range(double resolution, double max_range, int fallback, int wanted[3]);

// The BLAS's k^3 AABBs; primitive p = x + k * (y + k * z) is the box [x, x+1] x ... (enlarged).
std::vector<Aabb> block_aabbs(int block, float margin = kAabbMargin);

// TLAS instance i covers block (bx, by, bz) with x fastest; its translation is block * k.
void instance_block(const BlockGrid& s, uint64_t instance, int out[3]);
void instance_translation(const BlockGrid& s, uint64_t instance, float out[3]);

// The key of primitive `primitive` of instance `instance` in a window whose lowest key is lo.
// (The intersection shader does the same arithmetic with gl_InstanceID / gl_PrimitiveID.)
void voxel_key(const BlockGrid& s, const int lo[3], uint64_t instance, uint32_t primitive, int out[3]);

// Key-aligned windows covering `keys` widened by `margin` voxels (an exact segment that ends
// on a voxel face touches the voxel beyond it) and clamped to the key range. Unlike the
// compute back end's plan_windows (core/ray_space.h), which cuts by voxel count, the BVH has
// a fixed shape: the windows tile that box in a regular grid, each at most the block grid's
// size per axis, so each key lies in exactly one window.
std::vector<KeyBox> tile_windows(const KeyBox& keys, const BlockGrid& s, int margin = 1);

// The smallest direction component a traced ray gets (voxel units over t in [0, 1]). WHY:
// with an exactly zero component, a slab test written as box * (1/d) - o * (1/d) computes
// inf - inf = NaN, and the Vulkan spec leaves it to the implementation how that resolves.
// A component below this is set to +-kMinDirection: the ray drifts by at most 2^-20 voxel,
// far inside kAabbMargin, and the exact test still uses the true segment. (Defensive: no
// driver was seen to need it; it costs nothing.)
constexpr float kMinDirection = 1.0f / 1048576.0f;

// The direction traced from o to f in the window frame (f - o, small components lifted as
// above); the ray is traced over t in [0, 1]. The ray generation shader does the same.
void trace_direction(const float o[3], const float f[3], float out[3]);

// A map-frame point in window `lo`'s frame, voxel units: p * (1 / res) - (lo - 32768), in
// double then rounded to float (as the ray generation shader does).
void to_window_frame(const double p[3], double resolution, const int lo[3], float out[3]);

}  // namespace ort::rt
