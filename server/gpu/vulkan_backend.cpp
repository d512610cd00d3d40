// Placeholder until the compute back end lands (issue 2): refuses cleanly.
#include "gpu/vulkan_backend.h"

#include <stdexcept>

namespace ort {
std::unique_ptr<RayBackend> make_vulkan_backend(const BackendOptions&, std::string*) {
  throw std::runtime_error("the vulkan back end is not part of this build yet");
}
}  // namespace ort
