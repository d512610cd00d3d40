// OctoMap's DDA on four rays at once (AVX2, 64-bit lanes), for the cpu-grid back end.
//
// Why: the scalar walk's axis choice is a data-dependent branch that mispredicts often, and
// after the bricked grid the DDA itself was most of the walk. Here each lane takes the same
// double comparisons and additions as octomap_ray_walk.h (the axis choice as masks, the same
// three stop tests), so each ray visits the same keys; only the order of the marks differs,
// which the 2-bit OR does not see. Used only where the CPU says it has AVX2 (checked at run
// time; the build assumes nothing beyond x86-64).
// The mark's test is in lanes too: the voxel index computed from the lane's key, the four grid
// words gathered, and only visits that find their free bit unset queue a scalar mark (about
// one visit in 17 on fr079; the rest, mostly near the sensor, cost no scalar work and no
// branch on the grid's contents).
#pragma once

#include <cstddef>

#include "core/ray_batch.h"
#include "cpu/brick_layout.h"
#include "cpu/grid_marker.h"

namespace ort {

// True when this CPU runs AVX2 (and the build targets x86-64).
bool cpu_has_avx2();

// Walks rays [begin, end) of `b`, whose origin key must lie in the layout's window: marks the
// origin voxel and every free voxel of each ray inside the window, and each measured end
// inside the window as occupied, as the scalar walk does ray by ray.
void walk_rays_avx2(const RayBatch& b, size_t begin, size_t end, const BrickLayout& layout, double resolution,
                    GridMarker& marker);

// True when no walk of rays [begin, end) of `b` can leave the layout's window: the origin key
// and every end key lie at least two keys inside each face (judged from b.keys where
// b.keys_hold_ends, else ray by ray). A walk visits only voxels its segment passes through
// (it stops where the next border lies past the segment's length), inside the box of its
// origin and end keys give or take a voxel of rounding at a border; so one window holding a
// scan's whole ray space (widened by plan_windows' margin) passes, and a window of a split
// ray space or a tile's (its rays run on beyond it) does not. Where it holds, walk_rays_avx2
// drops the per-step test for leaving a row-by-row window. Needs AVX2, as walk_rays_avx2
// does (false in a build for another architecture).
bool rays_stay_inside(const RayBatch& b, size_t begin, size_t end, const BrickLayout& layout, double resolution);

}  // namespace ort
