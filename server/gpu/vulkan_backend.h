// The `vulkan` back end: compute shaders on any Vulkan 1.2 device with shaderFloat64.
#pragma once

#include <memory>
#include <string>

#include "engine/ray_backend.h"

namespace ort {

// Throws std::runtime_error (with the reason) when no usable Vulkan device exists.
std::unique_ptr<RayBackend> make_vulkan_backend(const BackendOptions& opts, std::string* log);

}  // namespace ort
