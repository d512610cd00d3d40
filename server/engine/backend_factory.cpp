// make_backend: picks and builds a ray-shooting back end. Automatic choice: rt where the
// device has the ray-tracing extensions, else vulkan compute, else cpu with a clear note.
#include "engine/backend_factory.h"

#include <stdexcept>

#include "core/cpu_backend.h"
#include "core/cpu_grid_backend.h"
#include "gpu/rt_backend.h"
#include "gpu/vulkan_backend.h"

namespace ort {

std::unique_ptr<RayBackend> make_backend(const BackendOptions& opts, std::string* log) {
  auto note = [&](const std::string& m) {
    if (log) *log += m + "\n";
  };
  switch (opts.kind) {
    case BackendKind::kCpu: return make_cpu_backend(opts.resolution);
    case BackendKind::kCpuGrid: return make_cpu_grid_backend({opts.resolution, opts.grid_budget_bytes, opts.threads});
    case BackendKind::kVulkan: return make_vulkan_backend(opts, log);
    case BackendKind::kRt: return make_rt_backend(opts, log);
    case BackendKind::kAuto: break;
  }
  try {
    return make_rt_backend(opts, log);
  } catch (const std::exception& e) {
    note(std::string("rt back end not used: ") + e.what());
  }
  try {
    return make_vulkan_backend(opts, log);
  } catch (const std::exception& e) {
    note(std::string("vulkan back end not used: ") + e.what() + "; using cpu");
  }
  return make_cpu_backend(opts.resolution);
}

}  // namespace ort
