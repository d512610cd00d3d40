// The `vulkan` back end: compute shaders on any Vulkan 1.2 device with shaderFloat64.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "core/ray_backend.h"

namespace ort {

// Knobs below BackendOptions, for tests and measurements; zero means automatic.
struct VulkanTuning {
  uint64_t output_voxels = 0;  // capacity of the voxel output (compaction chunks follow from it)
};

// Throws std::runtime_error (with the reason) when no usable Vulkan device exists.
std::unique_ptr<RayBackend> make_vulkan_backend(const BackendOptions& opts, std::string* log);
std::unique_ptr<RayBackend> make_vulkan_backend(const BackendOptions& opts, const VulkanTuning& tuning,
                                                std::string* log);

}  // namespace ort
