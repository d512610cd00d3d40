// The rt back end's ray-tracing pipeline: ray generation (rt_shoot.rgen), one miss shader
// (rt_miss.rmiss) and one procedural hit group with only an intersection shader
// (rt_voxel.rint); no closest-hit or any-hit work. Set 0: bindings 0..3 the storage buffers
// of the GPU ray space (shaders/ray_space.glsl: rays, grid, touched words, counters),
// binding 4 the TLAS. Push constants: gpu::ShootPush (server/gpu/shader_interface.h).
#pragma once

#include <cstdint>

#include <vulkan/vulkan.h>

#include "gpu/rt/block_grid.h"
#include "gpu/rt/rt_functions.h"
#include "gpu/vk/vk_buffer.h"
#include "gpu/vk/vk_context.h"
#include "gpu/vk/vk_pipeline_objects.h"

namespace ort::rt {

class RayTracingPipeline {
 public:
  // The grid's k and block counts are baked into the intersection shader as
  // specialization constants.
  RayTracingPipeline(const vk::Context& ctx, const RtFunctions& fn, const BlockGrid& grid, uint32_t push_bytes,
                     bool mark_candidates = false);
  RayTracingPipeline(const RayTracingPipeline&) = delete;
  RayTracingPipeline& operator=(const RayTracingPipeline&) = delete;

  // Binds rays, grid, touched, counters (bindings 0..3) and the TLAS (binding 4). Not while
  // a submitted command buffer uses the set.
  void bind(VkBuffer rays, VkBuffer grid, VkBuffer touched, VkBuffer counters, VkAccelerationStructureKHR tlas);
  // Binds pipeline + set, pushes constants, launches width x height rays.
  void trace(VkCommandBuffer cmd, const void* push, uint32_t width, uint32_t height) const;

 private:
  void create_pipeline(const RtFunctions& fn, const BlockGrid& grid, bool mark_candidates);
  void create_binding_table(const vk::Context& ctx, const RtFunctions& fn, uint32_t group_count);

  const RtFunctions* fn_;
  vk::PipelineObjects objects_;
  vk::Buffer sbt_;  // shader binding table: raygen, miss, hit group records
  VkStridedDeviceAddressRegionKHR raygen_{}, miss_{}, hit_{}, callable_{};
};

}  // namespace ort::rt
