// The `rt` back end: VK_KHR_ray_tracing_pipeline over a persistent shared BVH of voxel
// AABBs (one BLAS of k^3 voxels instanced by a TLAS), as in the OctoMap-RT paper.
#pragma once

#include <memory>
#include <string>

#include "core/log.h"
#include "core/ray_backend.h"

namespace ort {

// Throws Unsupported (core/errors.h) naming the missing extensions where the device lacks
// them, and for --traversal octomap; any other failure as std::runtime_error.
std::unique_ptr<RayBackend> make_rt_backend(const BackendOptions& opts, const Log& log = {});

}  // namespace ort
