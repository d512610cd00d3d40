// The seam between the engine and its ray-shooting back ends (cpu, vulkan, rt).
//
// A back end turns one RayBatch into the scan's consistent voxel states: every voxel a ray
// crosses is free, every measured end voxel is occupied, occupied wins, each key once.
#pragma once

#include <memory>
#include <string>

#include "engine/ray_batch.h"
#include "engine/voxel_update.h"

namespace ort {

enum class Traversal {
  kOctomap,  // OctoMap 1.9.7's computeRayKeys walk, bit for bit (the default)
  kExact,    // every voxel whose closed box the segment touches (the paper's geometry)
};

enum class BackendKind {
  kAuto,
  kCpu,      // OctoMap's computeRayKeys + KeySets: the reference
  kCpuGrid,  // native threads into the 2-bit shared ray space (engine/cpu_grid_backend.h)
  kVulkan,   // compute shaders (gpu/vulkan_backend.h)
  kRt,       // ray-tracing pipeline (gpu/rt_backend.h)
};

const char* to_string(Traversal t);
const char* to_string(BackendKind b);
bool parse_traversal(const std::string& s, Traversal& out);
bool parse_backend(const std::string& s, BackendKind& out);

// Wall-clock times of one scan's stages, milliseconds (paper Fig. 6 naming).
struct StageTimes {
  double prepare_ms = 0;   // CPU: validate, cut at max range, key box (prepare_scan)
  double upload_ms = 0;    // CPU -> GPU copy of the rays
  double shoot_ms = 0;     // ray shooting + 2-bit consistent states
  double compact_ms = 0;   // compaction of touched words + readback of the voxel list
  double octree_ms = 0;    // CPU octree update
  void add(const StageTimes& o) {
    prepare_ms += o.prepare_ms; upload_ms += o.upload_ms; shoot_ms += o.shoot_ms;
    compact_ms += o.compact_ms; octree_ms += o.octree_ms;
  }
  double total_ms() const { return prepare_ms + upload_ms + shoot_ms + compact_ms + octree_ms; }
};

// What one shoot() did, for progress output, status and the no-waste tests.
struct ShootStats {
  StageTimes times;
  uint64_t windows = 0;          // key-aligned windows the scan needed (>1: ray space > grid)
  uint64_t words_touched = 0;    // grid words listed as touched (= words read back and cleared)
  uint64_t words_read_back = 0;  // must equal words_touched: the window is never read whole
  uint64_t grid_words = 0;       // capacity of the persistent grid, in 32-bit words
  uint64_t grid_allocations = 0; // grid (re)allocations so far; stays 1 after start-up
};

class RayBackend {
 public:
  virtual ~RayBackend() = default;
  virtual BackendKind kind() const = 0;
  virtual std::string device_name() const = 0;
  // Shoots every ray of the batch; replaces `out` with the scan's voxel states.
  virtual void shoot(const RayBatch& batch, Traversal mode, VoxelList& out, ShootStats& stats) = 0;
};

struct BackendOptions {
  BackendKind kind = BackendKind::kAuto;
  std::string device;              // Vulkan device: name substring or index; empty = automatic
  double resolution = 0.1;
  double max_range = -1.0;         // sizes the persistent grid; < 0: no limit
  uint64_t grid_budget_bytes = 0;  // 0: automatic (capped by maxStorageBufferRange)
  Traversal traversal = Traversal::kOctomap;  // rt refuses octomap mode at creation, so auto moves on
  unsigned threads = 0;            // cpu-grid: ray threads, 0 = hardware threads
  bool verbose = false;
};

// Creates the requested back end. kAuto prefers rt, then vulkan, then cpu; with no Vulkan
// device at all it says so on `log` and returns cpu. An explicit kind that cannot be made
// throws std::runtime_error with a message that says why.
std::unique_ptr<RayBackend> make_backend(const BackendOptions& opts, std::string* log = nullptr);

}  // namespace ort
