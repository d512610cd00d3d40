// make_backend: the one place that knows every back end and builds the one asked for.
#pragma once

#include <memory>
#include <string>

#include "core/backend_kind.h"
#include "core/log.h"
#include "core/ray_backend.h"

namespace ort {

// Creates the requested back end. kAuto prefers rt, then vulkan on a GPU, then cpu-grid (also
// when the only Vulkan device is a CPU implementation such as lavapipe; backend_factory.cpp
// says why); with no Vulkan device at all it says so on `log`. It moves on only when a back end
// refuses with Unsupported (core/errors.h); any other failure (a device that fails to start,
// out of memory, a bug) is thrown as it is, for kAuto too. An explicit kind that cannot be
// made throws (Unsupported or std::runtime_error) with a message that says why.
std::unique_ptr<RayBackend> make_backend(const BackendOptions& opts, const Log& log = {});

}  // namespace ort
