// The persistent shared BVH of the rt back end (paper IV-B/IV-C): one BLAS of the k^3
// voxel AABBs of a block, one TLAS instancing it over the whole block grid. Built
// once at start-up; per scan only the rays move (block_grid.h), so nothing is rebuilt.
#pragma once

#include <cstdint>

#include <vulkan/vulkan.h>

#include "gpu/rt/block_grid.h"
#include "gpu/rt/rt_functions.h"
#include "gpu/vk/vk_buffer.h"
#include "gpu/vk/vk_commands.h"
#include "gpu/vk/vk_context.h"

namespace ort::rt {

// A VkAccelerationStructureKHR with the device-local buffer that holds it.
class AccelerationStructure {
 public:
  AccelerationStructure() = default;
  AccelerationStructure(const vk::Context& ctx, const RtFunctions& fn, VkAccelerationStructureTypeKHR type,
                        VkDeviceSize size);
  ~AccelerationStructure() { release(); }
  AccelerationStructure(AccelerationStructure&& o) noexcept { *this = static_cast<AccelerationStructure&&>(o); }
  AccelerationStructure& operator=(AccelerationStructure&& o) noexcept;
  AccelerationStructure(const AccelerationStructure&) = delete;
  AccelerationStructure& operator=(const AccelerationStructure&) = delete;

  VkAccelerationStructureKHR handle() const { return handle_; }
  VkDeviceAddress address() const;
  VkDeviceSize size() const { return size_; }  // bytes of GPU memory it holds

 private:
  void release();
  const RtFunctions* fn_ = nullptr;
  VkDevice device_ = VK_NULL_HANDLE;
  vk::Buffer buffer_;
  VkAccelerationStructureKHR handle_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
};

struct SharedBvh {
  AccelerationStructure blas;   // k^3 AABBs
  AccelerationStructure tlas;   // one instance per block of the grid
  double build_ms = 0;          // host wall clock: instance records, buffers, both builds
  double gpu_build_ms = 0;      // device timestamps around the two build commands
  uint64_t scratch_bytes = 0;   // freed after the build
  uint64_t instance_bytes = 0;  // freed after the build
};

// Builds the BLAS and the TLAS for this block grid and waits for them. The AABB, instance and
// scratch buffers are released before it returns: only blas + tlas stay on the GPU.
SharedBvh build_shared_bvh(const vk::Context& ctx, const RtFunctions& fn, const BlockGrid& grid,
                           vk::CommandRunner& runner, float aabb_margin = kAabbMargin);

}  // namespace ort::rt
