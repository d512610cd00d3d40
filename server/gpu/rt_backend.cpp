// Placeholder until the ray-tracing back end lands (issue 5): refuses cleanly.
#include "gpu/rt_backend.h"

#include <stdexcept>

namespace ort {
std::unique_ptr<RayBackend> make_rt_backend(const BackendOptions&, std::string*) {
  throw std::runtime_error(
      "unsupported: the rt back end needs VK_KHR_acceleration_structure and VK_KHR_ray_tracing_pipeline");
}
}  // namespace ort
