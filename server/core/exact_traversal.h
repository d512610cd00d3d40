// `exact` traversal on the CPU: every voxel whose closed box the segment touches.
//
// The predicate is one fixed double-precision slab test (segment_touches_voxel), written
// the same way in shaders/exact_slab.glsl, so the CPU and the GPU agree to the bit on
// ties (rays along faces, through edges and corners). This file enumerates candidates by
// sweeping x slabs, independently of the GPU's DDA walk, and serves as the reference.
#pragma once

#include <cstddef>  // OctoMap 1.9.7's OcTreeKey.h needs size_t and uint8_t declared first
#include <cstdint>
#include <vector>

#include <octomap/OcTreeKey.h>
#include <octomap/octomap_types.h>

namespace ort {

// Does the closed segment a->b touch the closed box of voxel key k at this resolution?
// Box bounds: (k - 32768) * res .. (k - 32767) * res, in double.
bool segment_touches_voxel(const double a[3], const double b[3], const int k[3], double res);

// Appends every touched key (each once) to out.
void exact_ray_keys(const octomap::point3d& origin, const octomap::point3d& end, double resolution,
                    std::vector<octomap::OcTreeKey>& out);

}  // namespace ort
