// The `vulkan` back end: compute shaders on any Vulkan 1.2 device with shaderFloat64.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "core/log.h"
#include "core/ray_backend.h"

namespace ort {

// Knobs below BackendOptions, for tests and measurements; zero means automatic.
struct VulkanTuning {
  uint64_t output_voxels = 0;  // capacity of the voxel output (compaction chunks follow from it)
  // The grid a ray space sized from the scans starts with (0: gpu::kStartGridWords); tests
  // start small to see it grow.
  uint64_t start_grid_words = 0;
};

// Throws Unsupported (core/errors.h, with the reason) when no usable Vulkan device exists;
// any other failure as std::runtime_error. The device and grid chosen go to `log`.
std::unique_ptr<RayBackend> make_vulkan_backend(const BackendOptions& opts, const Log& log = {});
std::unique_ptr<RayBackend> make_vulkan_backend(const BackendOptions& opts, const VulkanTuning& tuning,
                                                const Log& log = {});

}  // namespace ort
