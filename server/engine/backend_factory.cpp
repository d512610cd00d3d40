// make_backend: picks and builds a ray-shooting back end. Automatic choice: rt where the
// device has the ray-tracing extensions, else vulkan compute, else cpu with a clear note.
#include <stdexcept>

#include "engine/cpu_backend.h"
#include "engine/cpu_grid_backend.h"
#include "engine/ray_backend.h"
#include "gpu/rt_backend.h"
#include "gpu/vulkan_backend.h"

namespace ort {

const char* to_string(Traversal t) { return t == Traversal::kOctomap ? "octomap" : "exact"; }

const char* to_string(BackendKind b) {
  switch (b) {
    case BackendKind::kAuto: return "auto";
    case BackendKind::kCpu: return "cpu";
    case BackendKind::kCpuGrid: return "cpu-grid";
    case BackendKind::kVulkan: return "vulkan";
    case BackendKind::kRt: return "rt";
  }
  return "?";
}

bool parse_traversal(const std::string& s, Traversal& out) {
  if (s == "octomap") out = Traversal::kOctomap;
  else if (s == "exact") out = Traversal::kExact;
  else return false;
  return true;
}

bool parse_backend(const std::string& s, BackendKind& out) {
  if (s == "auto") out = BackendKind::kAuto;
  else if (s == "cpu") out = BackendKind::kCpu;
  else if (s == "cpu-grid") out = BackendKind::kCpuGrid;
  else if (s == "vulkan") out = BackendKind::kVulkan;
  else if (s == "rt") out = BackendKind::kRt;
  else return false;
  return true;
}

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
