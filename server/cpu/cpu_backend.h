// The `cpu` back end: OctoMap's own computeRayKeys (octomap mode) or the exact CPU
// reference (exact mode), with OctoMap's KeySets and "occupied wins". It is the reference
// the GPU back ends are tested against, and the fallback where there is no Vulkan device.
#pragma once

#include <memory>

#include "core/ray_backend.h"

namespace ort {

std::unique_ptr<RayBackend> make_cpu_backend(double resolution);

}  // namespace ort
