// make_backend: picks and builds a ray-shooting back end. Automatic choice: rt where the
// device has the ray-tracing extensions, else vulkan compute on a GPU, else cpu-grid (the
// native walk), with a note saying why. Only a typed refusal (Unsupported: no device, no ray
// tracing, traversal mode) moves the choice on; every other failure surfaces as it is.
//
// Why cpu-grid and not vulkan when the only Vulkan device is a CPU one (lavapipe, or any
// VK_PHYSICAL_DEVICE_TYPE_CPU): both then run the same walk into the same 2-bit grid on the
// same cores, lavapipe through a JIT-compiled shader and a driver (staging copies,
// submissions, atomics on a storage buffer), the native one with no driver in between.
// Measured on the 2-core dev machine (docs/history/benchmarks-log.md, "Performance (issue
// 12)"), the native walk needs less CPU time for the same scans. A timing probe at start-up was not
// taken: on a shared machine it measures the neighbours' load as much as the back ends, and
// the device type decides the same question deterministically.
#include "engine/backend_factory.h"

#include <string>

#include "core/errors.h"
#include "cpu/cpu_backend.h"
#include "cpu/cpu_grid_backend.h"
#include "gpu/rt_backend.h"
#include "gpu/vk/vk_context.h"
#include "gpu/vulkan_backend.h"

namespace ort {
namespace {

// Whether the device the vulkan back end would take is a CPU implementation.
bool automatic_device_is_cpu(const BackendOptions& opts) {
  vk::ContextOptions ctx;
  ctx.device = opts.device;
  return vk::Context(ctx).properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
}

}  // namespace

std::unique_ptr<RayBackend> make_backend(const BackendOptions& opts, const Log& log) {
  switch (opts.kind) {
    case BackendKind::kCpu: return make_cpu_backend(opts.resolution);
    case BackendKind::kCpuGrid:
      return make_cpu_grid_backend({opts.resolution, opts.grid_budget_bytes, opts.threads, true, opts.helpers_yield});
    case BackendKind::kVulkan: return make_vulkan_backend(opts, log);
    case BackendKind::kRt: return make_rt_backend(opts, log);
    case BackendKind::kAuto: break;
  }
  try {
    return make_rt_backend(opts, log);
  } catch (const Unsupported& e) {
    log.info(std::string("rt back end not used: ") + e.what());
  }
  try {
    if (automatic_device_is_cpu(opts)) {
      log.info(
          "vulkan back end not used: the Vulkan device is a CPU implementation; using cpu-grid (the native "
          "walk on the same cores)");
      return make_cpu_grid_backend({opts.resolution, opts.grid_budget_bytes, opts.threads, true, opts.helpers_yield});
    }
    return make_vulkan_backend(opts, log);
  } catch (const Unsupported& e) {
    log.info(std::string("vulkan back end not used: ") + e.what() + "; using cpu-grid");
  }
  return make_cpu_grid_backend({opts.resolution, opts.grid_budget_bytes, opts.threads, true, opts.helpers_yield});
}

}  // namespace ort
