// The list of ray-shooting back ends and the options every back end is made from. They live
// in the ground layer because the back ends themselves (core/ and gpu/) take these options
// and name their kind; engine/backend_factory.cpp is the one place that makes them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/traversal.h"

namespace ort {

enum class BackendKind {
  kAuto,
  kCpu,      // OctoMap's computeRayKeys + KeySets: the reference
  kCpuGrid,  // native threads into the 2-bit shared ray space (cpu/cpu_grid_backend.h)
  kVulkan,   // compute shaders (gpu/vulkan_backend.h)
  kRt,       // ray-tracing pipeline (gpu/rt_backend.h)
};

const char* to_string(BackendKind b);
bool parse_backend(const std::string& s, BackendKind& out);
// Every name parse_backend takes, "auto" first (the choices of --backend).
std::vector<std::string> backend_names();

struct BackendOptions {
  BackendKind kind = BackendKind::kAuto;
  std::string device;  // Vulkan device: name substring or index; empty = automatic
  double resolution = 0.1;
  double max_range = -1.0;                    // sizes the persistent grid; < 0: no limit
  uint64_t grid_budget_bytes = 0;             // 0: automatic (capped by maxStorageBufferRange)
  Traversal traversal = Traversal::kOctomap;  // rt refuses octomap mode at creation, so auto moves on
  unsigned threads = 0;                       // cpu-grid: ray threads, 0 = hardware threads
  bool gpu_prepare = true;  // vulkan: transform, max-range cut and keys in a shader (gpu/gpu_prepare.h)
  // vulkan on a discrete GPU: compaction writes the voxel list straight into host memory,
  // instead of device memory copied back in a submission of its own (one fence wait less a
  // scan: the daemon's choice, whose scans' lists are small; gpu/gpu_ray_space.h).
  bool compact_into_host_memory = false;
  // cpu-grid: the walk's helper threads run at the lowest priority, so that a stage 1 beside
  // the octree stage takes only the cores that stage leaves idle (set by MapEngine for the
  // batch programs; not the daemon: a starved helper would hold up a scan's latency).
  bool helpers_yield = false;
  bool verbose = false;
};

}  // namespace ort
