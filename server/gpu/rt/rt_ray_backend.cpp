// The rt back end: ray-tracing shaders shooting into the GPU ray space
// (gpu/gpu_ray_space.h), which owns the grid, the touched list, compaction and readback.
// This file holds only the shooting pass: per window, one ray per point traced through the
// persistent shared BVH of the block grid (the intersection shader marks crossed voxels
// free, the ray generation shader marks measured ends occupied), over windows that tile the
// scan's key box in the block grid's shape. Nothing is rebuilt or re-allocated per scan.
#include "gpu/rt/rt_ray_backend.h"

#include <algorithm>
#include <memory>
#include <stdexcept>

#include "core/errors.h"
#include "gpu/gpu_ray_space.h"
#include "gpu/rt/rt_accel.h"
#include "gpu/rt/rt_functions.h"
#include "gpu/rt/rt_pipeline.h"
#include "gpu/shader_interface.h"
#include "gpu/vk/vk_commands.h"
#include "gpu/vk/vk_context.h"

namespace ort::rt {

const char* const kOctomapModeRefusal =
    "unsupported: the rt back end implements --traversal exact only; OctoMap's walk (--traversal octomap) is a "
    "sequential DDA whose float steps and tie-breaking cannot be decided voxel by voxel in an intersection shader. "
    "Use --backend vulkan (or cpu) for octomap mode";

namespace {

constexpr const char* kNeeded =
    "VK_KHR_acceleration_structure, VK_KHR_ray_tracing_pipeline, VK_KHR_deferred_host_operations, "
    "bufferDeviceAddress and shaderFloat64";
constexpr uint32_t kLaunchWidth = 1u << 15;  // 2-D launches: width x ceil(rays / width)
constexpr int kWindowMargin = 1;             // a segment that ends on a voxel face touches the voxel beyond

std::shared_ptr<vk::Context> make_context(const BackendOptions& opts) {
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rt_features{};
  rt_features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR;
  rt_features.rayTracingPipeline = VK_TRUE;
  VkPhysicalDeviceAccelerationStructureFeaturesKHR as_features{};
  as_features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
  as_features.accelerationStructure = VK_TRUE;
  as_features.pNext = &rt_features;
  vk::ContextOptions co;
  co.device = opts.device;
  co.device_extensions = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME,
                          VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
  co.need_float64 = true;
  co.features12.bufferDeviceAddress = VK_TRUE;
  co.feature_chain = &as_features;
  try {
    return std::make_shared<vk::Context>(co);
  } catch (const Unsupported& e) {  // no device or no ray tracing; other failures surface as they are
    throw Unsupported(std::string("unsupported: the rt back end needs a Vulkan device with ") + kNeeded + "; " +
                      e.what());
  }
}

BlockGridLimits device_limits(const vk::Context& ctx, const BackendOptions& opts, BlockGridLimits l) {
  const auto as = acceleration_structure_properties(ctx.physical_device());
  l.max_instances = std::min<uint64_t>(l.max_instances, as.maxInstanceCount);
  // The grid is one storage buffer of 2-bit states: 4 voxels a byte.
  l.max_voxels = std::min<uint64_t>(l.max_voxels, uint64_t(ctx.properties().limits.maxStorageBufferRange) * 4);
  if (opts.grid_budget_bytes) l.max_voxels = std::min<uint64_t>(l.max_voxels, opts.grid_budget_bytes * 4);
  l.max_voxels = std::min<uint64_t>(l.max_voxels, uint64_t(1) << 32);  // 32-bit voxel index in the shaders
  return l;
}

BlockGrid block_grid_for(const vk::Context& ctx, const BackendOptions& opts, const RtOptions& rt) {
  int wanted[3] = {rt.wanted[0], rt.wanted[1], rt.wanted[2]};
  if (wanted[0] <= 0 || wanted[1] <= 0 || wanted[2] <= 0)
    wanted_from_range(opts.resolution, opts.max_range, 512, wanted);
  return choose_block_grid(rt.block, wanted, device_limits(ctx, opts, rt.limits));
}

// The ray space's grid holds the block grid's voxels. Compaction covers the touched list in
// chunks of at most 2^19 words, each writing at most 16 voxels a word straight into
// host-visible memory, so readback is what was touched, no more.
gpu::GpuRaySpaceOptions ray_space_options(const BlockGrid& grid) {
  gpu::GpuRaySpaceOptions o;
  o.sizing.grid_words = grid.grid_words();
  o.sizing.chunk_words = uint32_t(std::min<uint64_t>(o.sizing.grid_words, uint64_t(1) << 19));
  o.sizing.output_voxels = uint64_t(o.sizing.chunk_words) * gpu::kVoxelsPerWord;
  o.shoot_stage = VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR;
  o.voxels_in_host_memory = true;
  return o;
}

SharedBvh build_bvh(const vk::Context& ctx, const RtFunctions& fn, const BlockGrid& grid, float aabb_margin) {
  vk::CommandRunner runner(ctx);
  return build_shared_bvh(ctx, fn, grid, runner, aabb_margin);
}

class RtBackend final : public RayBackend {
 public:
  RtBackend(const BackendOptions& opts, const RtOptions& rt, const Log& log, RtBvhInfo* info)
      : ctx_(make_context(opts)),
        fn_(load_rt_functions(ctx_->device())),
        block_grid_(block_grid_for(*ctx_, opts, rt)),
        bvh_(build_bvh(*ctx_, fn_, block_grid_, rt.aabb_margin)),
        space_(ctx_, ray_space_options(block_grid_)),
        pipeline_(*ctx_, fn_, block_grid_, uint32_t(sizeof(gpu::ShootPush)), rt.mark_candidates) {
    space_.on_shoot_buffers([this](const gpu::ShootBuffers& b) {
      pipeline_.bind(b.rays, b.grid, b.touched, b.counters, bvh_.tlas.handle());
    });
    if (info) describe(*info);
    log.info("rt back end on " + ctx_->device_name() + ": block grid " + std::to_string(block_grid_.voxels(0)) + "x" +
             std::to_string(block_grid_.voxels(1)) + "x" + std::to_string(block_grid_.voxels(2)) + " voxels, BLAS of " +
             std::to_string(block_grid_.block) + "^3 boxes instanced " + std::to_string(block_grid_.instance_count()) +
             " times; BVH built in " + std::to_string(bvh_.build_ms) + " ms (BLAS " + std::to_string(bvh_.blas.size()) +
             " B, TLAS " + std::to_string(bvh_.tlas.size()) + " B)");
  }

  BackendKind kind() const override { return BackendKind::kRt; }
  std::string device_name() const override { return ctx_->device_name(); }

  void shoot(const RayBatch& batch, Traversal mode, VoxelList& out, ShootStats& stats) override {
    if (mode != Traversal::kExact) throw Unsupported(kOctomapModeRefusal);
    const std::vector<KeyBox> windows = tile_windows(batch.keys, block_grid_, kWindowMargin);
    space_.shoot(
        batch, windows, [&](VkCommandBuffer cmd, gpu::ShootPush push) { record_trace(cmd, push); }, out, stats);
  }

 private:
  // One ray per point, launched as width x ceil(rays / width).
  void record_trace(VkCommandBuffer cmd, const gpu::ShootPush& push) const {
    const uint32_t n = push.ray_count;
    const uint32_t width = std::min(n, kLaunchWidth), height = (n + width - 1) / width;
    pipeline_.trace(cmd, &push, width, height);
  }

  void describe(RtBvhInfo& info) const {
    info.block_grid = block_grid_;
    info.build_ms = bvh_.build_ms;
    info.gpu_build_ms = bvh_.gpu_build_ms;
    info.blas_bytes = bvh_.blas.size();
    info.tlas_bytes = bvh_.tlas.size();
    info.grid_bytes = block_grid_.grid_words() * 8;  // the 2-bit grid and its touched-word list
  }

  // Declared first: destroyed last (the BVH, the ray space and the pipeline share it).
  std::shared_ptr<vk::Context> ctx_;
  RtFunctions fn_;
  BlockGrid block_grid_;
  SharedBvh bvh_;
  gpu::GpuRaySpace space_;
  RayTracingPipeline pipeline_;
};

}  // namespace

std::unique_ptr<RayBackend> make_rt_backend(const BackendOptions& opts, const RtOptions& rt, const Log& log,
                                            RtBvhInfo* info) {
  if (opts.traversal == Traversal::kOctomap) throw Unsupported(kOctomapModeRefusal);
  return std::make_unique<RtBackend>(opts, rt, log, info);
}

}  // namespace ort::rt
