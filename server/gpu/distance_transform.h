// The exact squared Euclidean distance transform of a dense grid on the Vulkan device: the
// same three separable passes as server/distance/squared_edt.h (x: nearest obstacle in the
// row; y, z: integer lower envelopes), one invocation per line, in one submission. Same
// integers as the CPU one, bit for bit (tests/gpu/gpu_distance_test.cpp).
//
// Owns its own Context (its own VkDevice and queue), so it runs beside a mapping back end
// on the same GPU without sharing its queue across threads. Not thread-safe: one caller.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "gpu/vk/vk_buffer.h"
#include "gpu/vk/vk_commands.h"
#include "gpu/vk/vk_context.h"
#include "gpu/vk/vk_pipeline.h"

namespace ort::gpu {

// Must equal distance::kNoObstacle: a cell with no obstacle anywhere in the grid.
inline constexpr uint32_t kEdtNoObstacle = 0xFFFFFFFFu;
inline constexpr int kEdtMaxAxis = 8192;  // edt_lines.glsl's kMaxAxis

class DistanceTransform {
 public:
  // device: ContextOptions::device (index or name substring; "" automatic). Throws
  // ort::Unsupported where there is no usable Vulkan device.
  explicit DistanceTransform(const std::string& device = "");
  ~DistanceTransform();
  DistanceTransform(const DistanceTransform&) = delete;
  DistanceTransform& operator=(const DistanceTransform&) = delete;

  // out[i] = squared distance (cell units) of cell i = x + nx * (y + ny * z) to the nearest
  // cell with occupied != 0, kEdtNoObstacle without any.
  void run(std::span<const uint8_t> occupied, int nx, int ny, int nz, std::span<uint32_t> out);
  std::string device_name() const { return ctx_->device_name(); }
  // A CPU implementation of Vulkan (lavapipe): CPU threads are the better choice there.
  bool on_cpu_device() const { return ctx_->properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU; }
  // Wall time of the last run() [ms]: upload, the three passes, read-back.
  double last_device_ms() const { return last_device_ms_; }

 private:
  void ensure_capacity(uint64_t cells);

  std::shared_ptr<vk::Context> ctx_;
  bool unified_ = false;
  vk::CommandRunner runner_;
  vk::ComputePipeline rows_, envelope_;
  uint64_t capacity_ = 0;
  vk::Buffer occupied_, squared_, sites_, starts_, values_;  // working buffers
  vk::Buffer upload_, readback_;                             // discrete devices only
  double last_device_ms_ = 0;
};

}  // namespace ort::gpu
