// The seam between the engine and its ray-shooting back ends (cpu, cpu-grid, vulkan, rt).
//
// A back end turns one RayBatch into the scan's consistent voxel states: every voxel a ray
// crosses is free, every measured end voxel is occupied, occupied wins, each key once.
#pragma once

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

#include <octomap/octomap_types.h>

#include "core/backend_kind.h"
#include "core/prepare_scan.h"
#include "core/ray_batch.h"
#include "core/voxel_update.h"

namespace ort {

// Wall-clock times of one scan's stages, milliseconds (paper Fig. 6 naming).
struct StageTimes {
  double prepare_ms = 0;  // CPU: validate, cut at max range, key box (prepare_scan)
  double upload_ms = 0;   // CPU -> GPU copy of the rays
  double shoot_ms = 0;    // ray shooting + 2-bit consistent states
  double compact_ms = 0;  // compaction of touched words + readback of the voxel list
  double octree_ms = 0;   // CPU octree update
  // Parts of compact_ms on the GPU back ends (not added again by total_ms): the compaction
  // pass on the device's clock, the copy of the voxel list into host memory (a submission of
  // its own on discrete GPUs), and the host's copy of it into the scan's VoxelList.
  double compact_gpu_ms = 0;
  double readback_copy_ms = 0;
  double unpack_ms = 0;
  // Part of shoot_ms on the GPU back ends: the shooting pass on the device's clock (the rest
  // of shoot_ms is the submission and the wait for its fence).
  double shoot_gpu_ms = 0;
  void add(const StageTimes& o) {
    prepare_ms += o.prepare_ms;
    upload_ms += o.upload_ms;
    shoot_ms += o.shoot_ms;
    compact_ms += o.compact_ms;
    octree_ms += o.octree_ms;
    compact_gpu_ms += o.compact_gpu_ms;
    readback_copy_ms += o.readback_copy_ms;
    unpack_ms += o.unpack_ms;
    shoot_gpu_ms += o.shoot_gpu_ms;
  }
  double total_ms() const { return prepare_ms + upload_ms + shoot_ms + compact_ms + octree_ms; }
};

// What one shoot() did, for progress output, status and the no-waste tests.
struct ShootStats {
  StageTimes times;
  uint64_t windows = 0;           // key-aligned windows the scan needed (>1: ray space > grid)
  uint64_t words_touched = 0;     // grid words listed as touched (= words read back and cleared)
  uint64_t words_read_back = 0;   // must equal words_touched: the window is never read whole
  uint64_t grid_words = 0;        // capacity of the persistent grid, in 32-bit words
  uint64_t grid_allocations = 0;  // grid (re)allocations so far; stays 1 after start-up
  uint64_t walk_overruns = 0;     // rays stopped by a GPU shader's step guard: 0 on every valid input
};

// One scan as a sensor delivers it: points in the sensor frame, the pose that takes them
// into the map frame (OctoMap's Pointcloud::transform), the sensor origin in the map frame.
struct PosedPoints {
  const octomap::pose6d* pose = nullptr;
  octomap::point3d origin;
  // The points, x y z each (the layout of an octomap::point3d array and of a scan_t's xyz):
  // a device back end copies them as they lie, the receiver's buffer needs no repacking.
  std::span<const float> xyz;
  double max_range = -1.0;  // < 0: no limit
  // Bounds of what the device shoots in one go (0: none). When the scan's key box, widened by
  // the window margin, holds more voxels than max_box_voxels, or its walk bound (rays x the
  // box's key extents summed) exceeds max_walk_keys, nothing is shot and
  // PrepareReport::device_declined is set: the caller prepares on the CPU, where far-flung
  // scans are tiled along their rays and the per-scan limits apply (MapEngine::shoot).
  uint64_t max_box_voxels = 0;
  uint64_t max_walk_keys = 0;
  size_t point_count() const { return xyz.size() / 3; }
};

// An octomap::point3d array as its x y z floats (three floats a point, nothing between).
inline std::span<const float> as_xyz(std::span<const octomap::point3d> points) {
  static_assert(sizeof(octomap::point3d) == 3 * sizeof(float), "a point3d is its three floats");
  return {points.empty() ? nullptr : &points[0](0), points.size() * 3};
}

class RayBackend {
 public:
  virtual ~RayBackend() = default;
  virtual BackendKind kind() const = 0;
  virtual std::string device_name() const = 0;
  // Shoots every ray of the batch; replaces `out` with the scan's voxel states.
  virtual void shoot(const RayBatch& batch, Traversal mode, VoxelList& out, ShootStats& stats) = 0;

  // True when this back end prepares scans on its device (shoot_posed); the engine then
  // hands it sensor-frame points instead of a RayBatch.
  virtual bool prepares_on_device() const { return false; }
  // The transform and prepare_scan's rules on the device, with the same rays bit for bit,
  // then the shot. Fills `report` as prepare_scan does, and stats.times.prepare_ms.
  virtual void shoot_posed(const PosedPoints& scan, Traversal mode, VoxelList& out, ShootStats& stats,
                           PrepareReport& report) {
    (void)scan, (void)mode, (void)out, (void)stats, (void)report;
    throw std::logic_error("this back end does not prepare scans on its device");
  }
};

}  // namespace ort
