// The `rt` back end behind the engine's seam, with the knobs the benchmark sweeps.
#pragma once

#include <memory>
#include <string>

#include "core/log.h"
#include "core/ray_backend.h"
#include "gpu/rt/block_grid.h"

namespace ort::rt {

struct RtOptions {
  int block = 4;                    // k: voxels along a BLAS edge (2..8; the paper's 2^3..2^9 boxes)
  int wanted[3] = {0, 0, 0};        // block grid, voxels per axis; 0: from max range (or 512)
  BlockGridLimits limits;           // caps on grid voxels and TLAS instances (windows beyond)
  float aabb_margin = kAabbMargin;  // enlargement of the BLAS boxes (block_grid.h says why)
  bool mark_candidates = false;     // diagnosis: mark every box the traversal reports, no exact test
};

// What start-up built, for status output and the Table III benchmark.
struct RtBvhInfo {
  BlockGrid block_grid;
  double build_ms = 0;      // host wall clock of the whole BVH build
  double gpu_build_ms = 0;  // device time of the two build commands
  uint64_t blas_bytes = 0;  // GPU memory of the BLAS
  uint64_t tlas_bytes = 0;  // GPU memory of the TLAS
  uint64_t grid_bytes = 0;  // the 2-bit state grid + touched-word list
};

// The device must have VK_KHR_acceleration_structure, VK_KHR_ray_tracing_pipeline,
// VK_KHR_deferred_host_operations, bufferDeviceAddress and shaderFloat64; otherwise this
// throws Unsupported("unsupported: ... lacks ...") (core/errors.h). It also refuses
// Traversal::kOctomap (OctoMap's sequential DDA is not a geometric predicate per voxel).
std::unique_ptr<RayBackend> make_rt_backend(const BackendOptions& opts, const RtOptions& rt, const Log& log = {},
                                            RtBvhInfo* info = nullptr);

// The message of the refusal of --traversal octomap (also used by --help texts and docs).
extern const char* const kOctomapModeRefusal;

}  // namespace ort::rt
