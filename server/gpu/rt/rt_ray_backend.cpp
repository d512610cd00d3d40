// The rt back end: per scan, the rays are uploaded once; for each key-aligned window of the
// scan, one submission traces them through the persistent shared BVH (the intersection
// shader marks crossed voxels free, the ray generation shader marks measured ends occupied,
// both with atomicOr into the 2-bit grid, listing touched words), then the compute back
// end's compaction shader turns the touched words into VoxelUpdates in host-visible memory
// and clears them. Nothing is rebuilt or re-allocated per scan.
#include "gpu/rt/rt_ray_backend.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <stdexcept>

#include "gpu/rt/rt_accel.h"
#include "gpu/rt/rt_functions.h"
#include "gpu/rt/rt_pipeline.h"
#include "gpu/shader_interface.h"
#include "gpu/vk/vk_buffer.h"
#include "gpu/vk/vk_commands.h"
#include "gpu/vk/vk_context.h"
#include "gpu/vk/vk_pipeline.h"
#include "gpu/vk/vk_timestamps.h"
#include "shaders/compact_touched_spv.h"

namespace ort::rt {

const char* const kOctomapModeRefusal =
    "unsupported: the rt back end implements --traversal exact only; OctoMap's walk (--traversal octomap) is a "
    "sequential DDA whose float steps and tie-breaking cannot be decided voxel by voxel in an intersection shader. "
    "Use --backend vulkan (or cpu) for octomap mode";

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

constexpr const char* kNeeded =
    "VK_KHR_acceleration_structure, VK_KHR_ray_tracing_pipeline, VK_KHR_deferred_host_operations, "
    "bufferDeviceAddress and shaderFloat64";
constexpr uint32_t kLaunchWidth = 1u << 15;  // 2-D launches: width x ceil(rays / width)

std::unique_ptr<vk::Context> make_context(const BackendOptions& opts) {
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
    return std::make_unique<vk::Context>(co);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("unsupported: the rt back end needs a Vulkan device with ") + kNeeded +
                             "; " + e.what());
  }
}

SpaceLimits device_limits(const vk::Context& ctx, const BackendOptions& opts, SpaceLimits l) {
  const auto as = acceleration_structure_properties(ctx.physical_device());
  l.max_instances = std::min<uint64_t>(l.max_instances, as.maxInstanceCount);
  // The grid is one storage buffer of 2-bit states: 4 voxels a byte.
  l.max_voxels = std::min<uint64_t>(l.max_voxels, uint64_t(ctx.properties().limits.maxStorageBufferRange) * 4);
  if (opts.grid_budget_bytes) l.max_voxels = std::min<uint64_t>(l.max_voxels, opts.grid_budget_bytes * 4);
  l.max_voxels = std::min<uint64_t>(l.max_voxels, uint64_t(1) << 32);  // 32-bit voxel index in the shaders
  return l;
}

class RtBackend final : public RayBackend {
 public:
  RtBackend(const BackendOptions& opts, const RtOptions& rt, std::string* log, RtBvhInfo* info)
      : ctx_(make_context(opts)), fn_(load_rt_functions(ctx_->device())) {
    int wanted[3] = {rt.wanted[0], rt.wanted[1], rt.wanted[2]};
    if (wanted[0] <= 0 || wanted[1] <= 0 || wanted[2] <= 0) wanted_from_range(opts.resolution, opts.max_range, 512, wanted);
    layout_ = choose_layout(rt.block, wanted, device_limits(*ctx_, opts, rt.limits));
    runner_ = std::make_unique<vk::CommandRunner>(*ctx_);
    bvh_ = build_shared_bvh(*ctx_, fn_, layout_, *runner_, rt.aabb_margin);
    pipeline_ = std::make_unique<RayTracingPipeline>(*ctx_, fn_, layout_, uint32_t(sizeof(gpu::ShootPush)),
                                                     rt.mark_candidates);
    compact_ = std::make_unique<vk::ComputePipeline>(*ctx_, compact_touched_spv, 4, uint32_t(sizeof(gpu::CompactPush)));
    stamps_ = std::make_unique<vk::TimestampQueries>(*ctx_, 3);

    const VkMemoryPropertyFlags local = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    const uint64_t words = layout_.grid_words();
    grid_ = vk::Buffer(*ctx_, words * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, local);
    touched_ = vk::Buffer(*ctx_, words * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, local);
    counters_ = vk::Buffer(*ctx_, 64,
                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                               VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                           local);
    readback_ = vk::Buffer(*ctx_, 64, VK_BUFFER_USAGE_TRANSFER_DST_BIT, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                           VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    // Compaction covers the touched list in chunks; each chunk writes at most 16 voxels a
    // word straight into host-visible memory, so readback is what was touched, no more.
    chunk_words_ = uint32_t(std::min<uint64_t>(words, uint64_t(1) << 19));
    voxels_ = vk::Buffer(*ctx_, uint64_t(chunk_words_) * gpu::kVoxelsPerWord * sizeof(VoxelUpdate),
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                         VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    ensure_ray_capacity(1 << 16);
    compact_->bind_buffers({grid_.handle(), touched_.handle(), counters_.handle(), voxels_.handle()});

    VkCommandBuffer cmd = runner_->begin();  // the grid starts clean; compaction keeps it so
    vkCmdFillBuffer(cmd, grid_.handle(), 0, VK_WHOLE_SIZE, 0);
    runner_->submit_and_wait();

    if (info) {
      info->layout = layout_;
      info->build_ms = bvh_.build_ms;
      info->gpu_build_ms = bvh_.gpu_build_ms;
      info->blas_bytes = bvh_.blas.size();
      info->tlas_bytes = bvh_.tlas.size();
      info->grid_bytes = words * 8;
    }
    if (log) {
      *log += "rt back end on " + ctx_->device_name() + ": shared ray space " + std::to_string(layout_.voxels(0)) + "x" +
              std::to_string(layout_.voxels(1)) + "x" + std::to_string(layout_.voxels(2)) + " voxels, BLAS of " +
              std::to_string(layout_.block) + "^3 boxes instanced " + std::to_string(layout_.instance_count()) +
              " times; BVH built in " + std::to_string(bvh_.build_ms) + " ms (BLAS " + std::to_string(bvh_.blas.size()) +
              " B, TLAS " + std::to_string(bvh_.tlas.size()) + " B)\n";
    }
  }

  BackendKind kind() const override { return BackendKind::kRt; }
  std::string device_name() const override { return ctx_->device_name(); }

  void shoot(const RayBatch& batch, Traversal mode, VoxelList& out, ShootStats& stats) override {
    if (mode != Traversal::kExact) throw std::runtime_error(kOctomapModeRefusal);
    out.clear();
    stats.grid_words = layout_.grid_words();
    stats.grid_allocations = 1;  // grid, touched list and BVH are made once, at start-up
    const uint32_t n = uint32_t(batch.ends.size());
    if (n == 0) return;

    auto t = Clock::now();
    ensure_ray_capacity(n);
    std::memcpy(staging_.mapped(), batch.ends.data(), size_t(n) * sizeof(RayEnd));
    staging_.flush();
    stats.times.upload_ms += ms_since(t);

    gpu::ShootPush push{};
    push.resolution = batch.resolution;
    push.resolution_factor = 1.0 / batch.resolution;  // as OctoMap keeps it
    push.origin[0] = batch.origin.x();
    push.origin[1] = batch.origin.y();
    push.origin[2] = batch.origin.z();
    push.ray_count = n;
    push.first_chunk_words = chunk_words_;
    push.ray_base = 0;
    for (int i = 0; i < 3; ++i) push.origin_key[i] = batch.origin_key[i];
    const uint32_t width = std::min(n, kLaunchWidth), height = (n + width - 1) / width;

    bool first = true;
    for (const KeyBox& w : plan_windows(batch.keys, layout_)) {
      ++stats.windows;
      t = Clock::now();
      gpu::CompactPush cp{};
      for (int i = 0; i < 3; ++i) {
        push.win_lo[i] = cp.win_lo[i] = w.lo[i];
        push.win_n[i] = cp.win_n[i] = uint32_t(w.hi[i] - w.lo[i] + 1);
      }
      cp.chunk_begin = 0;
      cp.chunk_words = chunk_words_;

      VkCommandBuffer cmd = runner_->begin();
      stamps_->reset(cmd);
      if (first) {
        const VkBufferCopy copy{0, 0, VkDeviceSize(n) * sizeof(RayEnd)};
        vkCmdCopyBuffer(cmd, staging_.handle(), rays_.handle(), 1, &copy);
        first = false;
      }
      const gpu::Counters init{0, 1, 1, 0, 0, 0, 0};
      vkCmdUpdateBuffer(cmd, counters_.handle(), 0, sizeof(init), &init);
      vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                         VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
      stamps_->write(cmd, 0, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
      pipeline_->trace(cmd, &push, width, height);
      stamps_->write(cmd, 1, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
      vk::memory_barrier(cmd, VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR, VK_ACCESS_SHADER_WRITE_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
      compact_->dispatch_indirect(cmd, &cp, counters_.handle(), 0);
      finish_compaction(cmd);
      stamps_->write(cmd, 2, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
      runner_->submit_and_wait();
      stamps_->fetch(3);
      const double trace_ms = stamps_->supported() ? stamps_->elapsed_ms(0, 1) : 0.0;

      const gpu::Counters c = read_counters();
      append_voxels(c.emitted_count, out);
      // Lists longer than one chunk: compact the rest chunk by chunk (rare: > 8M voxels).
      for (uint32_t begin = chunk_words_; begin < c.touched_count; begin += chunk_words_) {
        cmd = runner_->begin();
        vkCmdFillBuffer(cmd, counters_.handle(), gpu::kEmittedOffset, 4, 0);
        vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                           VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
        cp.chunk_begin = begin;
        const uint32_t words = std::min(chunk_words_, c.touched_count - begin);
        compact_->dispatch(cmd, &cp, (words + gpu::kCompactGroup - 1) / gpu::kCompactGroup);
        finish_compaction(cmd);
        runner_->submit_and_wait();
        append_voxels(read_counters().emitted_count, out);
      }
      stats.words_touched += c.touched_count;
      stats.words_read_back += c.touched_count;
      const double window_ms = ms_since(t);
      const double shoot_ms = trace_ms > 0 ? std::min(trace_ms, window_ms) : window_ms;
      stats.times.shoot_ms += shoot_ms;
      stats.times.compact_ms += window_ms - shoot_ms;
    }
  }

 private:
  // Compaction writes visible to the transfer that copies the counters and to the host.
  void finish_compaction(VkCommandBuffer cmd) {
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                       VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT);
    const VkBufferCopy copy{0, 0, sizeof(gpu::Counters)};
    vkCmdCopyBuffer(cmd, counters_.handle(), readback_.handle(), 1, &copy);
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                       VK_ACCESS_HOST_READ_BIT);
  }

  gpu::Counters read_counters() const {
    readback_.invalidate();
    gpu::Counters c;
    std::memcpy(&c, readback_.mapped(), sizeof(c));
    return c;
  }

  void append_voxels(uint32_t count, VoxelList& out) const {
    if (count == 0) return;
    if (uint64_t(count) > uint64_t(chunk_words_) * gpu::kVoxelsPerWord) {
      throw std::runtime_error("rt back end: compaction emitted more voxels than a chunk holds");
    }
    voxels_.invalidate();
    const size_t old = out.size();
    out.resize(old + count);
    std::memcpy(out.data() + old, voxels_.mapped(), size_t(count) * sizeof(VoxelUpdate));
  }

  // Ray buffers grow geometrically (never per scan once a scan of that size has been seen).
  void ensure_ray_capacity(uint32_t rays) {
    const VkDeviceSize need = VkDeviceSize(rays) * sizeof(RayEnd);
    if (rays_ && rays_.size() >= need) return;
    VkDeviceSize size = rays_ ? rays_.size() : 0;
    size = std::max<VkDeviceSize>(need, size * 2);
    rays_ = vk::Buffer(*ctx_, size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                       VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    staging_ = vk::Buffer(*ctx_, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                          VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    pipeline_->bind(rays_.handle(), grid_.handle(), touched_.handle(), counters_.handle(), bvh_.tlas.handle());
  }

  std::unique_ptr<vk::Context> ctx_;
  RtFunctions fn_;
  SpaceLayout layout_;
  std::unique_ptr<vk::CommandRunner> runner_;
  SharedBvh bvh_;
  std::unique_ptr<RayTracingPipeline> pipeline_;
  std::unique_ptr<vk::ComputePipeline> compact_;
  std::unique_ptr<vk::TimestampQueries> stamps_;
  vk::Buffer grid_, touched_, counters_, readback_, voxels_, rays_, staging_;
  uint32_t chunk_words_ = 0;
};

}  // namespace

std::unique_ptr<RayBackend> make_rt_backend(const BackendOptions& opts, const RtOptions& rt, std::string* log,
                                            RtBvhInfo* info) {
  if (opts.traversal == Traversal::kOctomap) throw std::runtime_error(kOctomapModeRefusal);
  return std::make_unique<RtBackend>(opts, rt, log, info);
}

}  // namespace ort::rt
