// Scan preparation on the GPU: the CPU's preparation (engine/map_frame.h transform +
// engine/prepare_scan.h rules) as one compute pass, shaders/prepare_rays.comp.
//
// The host copies the sensor-frame points (12 bytes a point) and pushes the pose; the pass
// writes ray i for point i into the ray space's rays buffer, exactly the RayEnd the CPU
// makes for it (bit for bit), or a ray flagged kRayEndDropped where the CPU drops the point,
// and reduces the key box of the kept ends and the counts into a small result the host
// reads back for window planning and the PrepareReport. One submission, waited for.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include <vulkan/vulkan.h>

#include <octomap/octomap_types.h>

#include "core/ray_batch.h"
#include "gpu/vk/vk_buffer.h"
#include "gpu/vk/vk_commands.h"
#include "gpu/vk/vk_context.h"
#include "gpu/vk/vk_pipeline.h"

namespace ort::gpu {

// What a scan's preparation needs besides its points.
struct ScanFrame {
  octomap::pose6d pose;     // sensor frame -> map frame
  octomap::point3d origin;  // sensor origin, map frame
  double max_range = -1.0;  // < 0: no limit
  double resolution = 0.1;
};

// What came back: the key box of the kept ray ends (origin not included) and the counts.
struct DevicePrepared {
  KeyBox end_keys;
  uint64_t nonfinite = 0, out_of_range = 0, cut_at_max_range = 0, degenerate = 0, read_as_zero = 0;
};

// The largest float |p - origin|^2 whose OctoMap norm (sqrt in double) is <= max_range,
// or -1 when none is (max_range NaN). The pass decides the max-range cut with it.
float norm_sq_limit(double max_range);

class GpuPrepare {
 public:
  explicit GpuPrepare(std::shared_ptr<const vk::Context> ctx);
  GpuPrepare(const GpuPrepare&) = delete;
  GpuPrepare& operator=(const GpuPrepare&) = delete;

  // Copies the points (x y z floats each) where the pass reads them (a staging buffer on
  // discrete GPUs).
  void stage_points(std::span<const float> sensor_xyz);
  // Prepares the staged points into rays[0, n) of `rays` (room for n rays), and waits.
  DevicePrepared run(const ScanFrame& frame, VkBuffer rays);

 private:
  void ensure_point_capacity(uint64_t points);
  void bind(VkBuffer rays);
  void record(VkCommandBuffer cmd, const ScanFrame& frame);

  // Declared first: destroyed last.
  std::shared_ptr<const vk::Context> ctx_;
  bool unified_ = false;
  vk::CommandRunner runner_;
  vk::ComputePipeline pass_;
  vk::Buffer points_staging_, points_;   // points_staging_: discrete GPUs only
  vk::Buffer result_, result_readback_;  // result_readback_: discrete GPUs only
  uint64_t point_capacity_ = 0;
  uint64_t staged_points_ = 0;
  VkBuffer bound_rays_ = VK_NULL_HANDLE;
  bool bound_ = false;
  uint32_t max_groups_;
};

}  // namespace ort::gpu
