// The seam between the engine and its ray-shooting back ends (cpu, cpu-grid, vulkan, rt).
//
// A back end turns one RayBatch into the scan's consistent voxel states: every voxel a ray
// crosses is free, every measured end voxel is occupied, occupied wins, each key once.
#pragma once

#include <cstdint>
#include <string>

#include "core/backend_kind.h"
#include "core/ray_batch.h"
#include "core/voxel_update.h"

namespace ort {

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

}  // namespace ort
