// The engine's entry to the ray-tracing back end (server/gpu/rt/): default knobs (BLAS block
// k = 4, shared ray space from max range). Where the device lacks the ray-tracing
// extensions, or for --traversal octomap, it throws Unsupported ("unsupported: ...") and the
// automatic choice moves on to the vulkan compute back end.
#include "gpu/rt_backend.h"

#include "gpu/rt/rt_ray_backend.h"

namespace ort {

std::unique_ptr<RayBackend> make_rt_backend(const BackendOptions& opts, const Log& log) {
  return rt::make_rt_backend(opts, rt::RtOptions{}, log);
}

}  // namespace ort
