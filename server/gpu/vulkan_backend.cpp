// The `vulkan` back end: compute shaders over a persistent shared ray space.
//
// Per scan: the rays go up once (through a staging buffer that only ever grows); for each
// key-aligned window of the scan's ray space one submission runs
//   shoot (one invocation per ray: atomicOr of 2-bit states, first touch lists the word)
//   -> compact (one invocation per listed word, indirect dispatch: emit voxels, clear word);
// then the host reads the emitted count and exactly that many voxels. Nothing is sized per
// scan, and nothing scales with the window: the grid is cleared through the touched list.
#include "gpu/vulkan_backend.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "gpu/ray_space_sizing.h"
#include "engine/ray_space.h"
#include "gpu/shader_interface.h"
#include "gpu/vk/vk_buffer.h"
#include "gpu/vk/vk_check.h"
#include "gpu/vk/vk_commands.h"
#include "gpu/vk/vk_context.h"
#include "gpu/vk/vk_pipeline.h"
#include "gpu/vk/vk_timestamps.h"
#include "shaders/compact_touched_spv.h"
#include "shaders/shoot_exact_spv.h"
#include "shaders/shoot_octomap_spv.h"

namespace ort {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

constexpr int kWindowMargin = 2;          // voxels around the key box: the walk may overstep by one
constexpr uint64_t kMinRayCapacity = 1 << 16;
constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;

// Timestamp slots of one window's submission.
enum Stamp : uint32_t { kStampStart, kStampUploaded, kStampShot, kStampCompacted, kStampCount };

class VulkanBackend final : public RayBackend {
 public:
  VulkanBackend(const BackendOptions& opts, const VulkanTuning& tuning, std::string* log) {
    vk::ContextOptions co;
    co.device = opts.device;
    co.need_float64 = true;  // OctoMap's tMax/tDelta are doubles
    ctx_ = std::make_unique<vk::Context>(co);
    unified_ = ctx_->unified_memory();
    const VkPhysicalDeviceLimits& limits = ctx_->properties().limits;
    max_groups_ = limits.maxComputeWorkGroupCount[0];
    const uint64_t budget = opts.grid_budget_bytes
                                ? opts.grid_budget_bytes
                                : gpu::auto_grid_budget(limits.maxStorageBufferRange, ctx_->device_local_bytes());
    sizing_ = gpu::size_ray_space(opts.max_range, opts.resolution, budget, limits.maxStorageBufferRange, max_groups_,
                                  tuning.output_voxels);

    // Unified memory (lavapipe, integrated GPUs): everything host-visible, read and written
    // in place. Discrete GPUs: device-local working buffers, host-visible staging.
    const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    const VkMemoryPropertyFlags work_required = unified_ ? host : VkMemoryPropertyFlags(VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    const VkMemoryPropertyFlags work_preferred = unified_ ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT : 0;
    grid_ = vk::Buffer(*ctx_, sizing_.grid_words * 4, kStorage, work_required, work_preferred);
    ++grid_allocations_;
    touched_ = vk::Buffer(*ctx_, sizing_.grid_words * 4, kStorage, work_required, work_preferred);
    counters_ = vk::Buffer(*ctx_, sizeof(gpu::Counters), kStorage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                           work_required, work_preferred);
    voxels_ = vk::Buffer(*ctx_, sizing_.output_voxels * sizeof(VoxelUpdate), kStorage, work_required, work_preferred);
    if (!unified_) {
      const VkMemoryPropertyFlags cached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
      counters_readback_ = vk::Buffer(*ctx_, sizeof(gpu::Counters), kStorage, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, cached);
      voxels_readback_ = vk::Buffer(*ctx_, voxels_.size(), kStorage, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, cached);
    }

    shoot_octomap_ = std::make_unique<vk::ComputePipeline>(*ctx_, shoot_octomap_spv, 4, sizeof(gpu::ShootPush));
    shoot_exact_ = std::make_unique<vk::ComputePipeline>(*ctx_, shoot_exact_spv, 4, sizeof(gpu::ShootPush));
    compact_ = std::make_unique<vk::ComputePipeline>(*ctx_, compact_touched_spv, 4, sizeof(gpu::CompactPush));
    compact_->bind_buffers({grid_.handle(), touched_.handle(), counters_.handle(), voxels_.handle()});
    runner_ = std::make_unique<vk::CommandRunner>(*ctx_);
    timestamps_ = std::make_unique<vk::TimestampQueries>(*ctx_, kStampCount);
    ensure_ray_capacity(kMinRayCapacity);

    // The grid starts clear, once; from then on only the compact pass clears it.
    VkCommandBuffer cmd = runner_->begin();
    vkCmdFillBuffer(cmd, grid_.handle(), 0, VK_WHOLE_SIZE, 0);
    runner_->submit_and_wait();

    name_ = ctx_->device_name() + " (" + vk::device_type_name(ctx_->properties().deviceType) + ")";
    if (log) {
      *log += "vulkan: " + name_ + ", grid " + std::to_string((sizing_.grid_words * 4 + 1023) >> 10) + " KiB (" +
              std::to_string(sizing_.grid_words * gpu::kVoxelsPerWord) + " voxels), " +
              (unified_ ? "unified memory" : "device-local memory with staging") + "\n";
    }
  }

  BackendKind kind() const override { return BackendKind::kVulkan; }
  std::string device_name() const override { return name_; }

  void shoot(const RayBatch& batch, Traversal mode, VoxelList& out, ShootStats& stats) override {
    out.clear();
    stats.grid_words = sizing_.grid_words;
    stats.grid_allocations = grid_allocations_;
    if (batch.ends.empty()) return;
    if (batch.ends.size() > UINT32_MAX) throw std::runtime_error("vulkan back end: more than 2^32 rays in one scan");

    const auto t_upload = Clock::now();
    ensure_ray_capacity(batch.ends.size());
    const size_t ray_bytes = batch.ends.size() * sizeof(RayEnd);
    std::memcpy(unified_ ? rays_.mapped() : rays_staging_.mapped(), batch.ends.data(), ray_bytes);
    (unified_ ? rays_ : rays_staging_).flush();
    stats.times.upload_ms += ms_since(t_upload);

    const std::vector<KeyBox> windows =
        plan_windows(batch.keys, sizing_.grid_words * gpu::kVoxelsPerWord, kWindowMargin);
    vk::ComputePipeline& shoot = mode == Traversal::kOctomap ? *shoot_octomap_ : *shoot_exact_;
    for (size_t w = 0; w < windows.size(); ++w) {
      run_window(batch, shoot, windows[w], w == 0 ? ray_bytes : 0, out, stats);
    }
    stats.windows += windows.size();
  }

 private:
  // Rays buffers only grow (geometrically), so a steady stream of scans allocates nothing.
  void ensure_ray_capacity(uint64_t rays) {
    if (rays <= ray_capacity_) return;
    const uint64_t capacity = std::max({rays, 2 * ray_capacity_, kMinRayCapacity});
    const VkDeviceSize bytes = capacity * sizeof(RayEnd);
    const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    if (unified_) {
      rays_ = vk::Buffer(*ctx_, bytes, kStorage, host, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    } else {
      rays_staging_ = vk::Buffer(*ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, host);
      rays_ = vk::Buffer(*ctx_, bytes, kStorage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    }
    ray_capacity_ = capacity;
    for (vk::ComputePipeline* p : {shoot_octomap_.get(), shoot_exact_.get()}) {
      p->bind_buffers({rays_.handle(), grid_.handle(), touched_.handle(), counters_.handle()});
    }
  }

  const gpu::Counters& read_counters() const {
    const vk::Buffer& b = unified_ ? counters_ : counters_readback_;
    b.invalidate();
    return *b.as<gpu::Counters>();
  }

  // Copies counters to the host-visible mirror (discrete GPUs) at the end of a submission.
  void record_counters_readback(VkCommandBuffer cmd) {
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                       VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT);
    if (unified_) return;
    const VkBufferCopy region{0, 0, sizeof(gpu::Counters)};
    vkCmdCopyBuffer(cmd, counters_.handle(), counters_readback_.handle(), 1, &region);
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                       VK_ACCESS_HOST_READ_BIT);
  }

  void run_window(const RayBatch& batch, const vk::ComputePipeline& shoot, const KeyBox& w, size_t upload_bytes,
                  VoxelList& out, ShootStats& stats) {
    gpu::ShootPush sp{};
    sp.resolution = batch.resolution;
    sp.resolution_factor = 1.0 / batch.resolution;
    sp.origin[0] = batch.origin.x();
    sp.origin[1] = batch.origin.y();
    sp.origin[2] = batch.origin.z();
    sp.ray_count = uint32_t(batch.ends.size());
    sp.first_chunk_words = sizing_.chunk_words;
    gpu::CompactPush cp{};
    for (int i = 0; i < 3; ++i) {
      sp.win_lo[i] = cp.win_lo[i] = w.lo[i];
      sp.win_n[i] = cp.win_n[i] = uint32_t(w.hi[i] - w.lo[i] + 1);
      sp.origin_key[i] = batch.origin_key[i];
    }
    cp.chunk_begin = 0;
    cp.chunk_words = sizing_.chunk_words;

    const auto t_submit = Clock::now();
    VkCommandBuffer cmd = runner_->begin();
    timestamps_->reset(cmd);
    timestamps_->write(cmd, kStampStart, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
    if (upload_bytes && !unified_) {
      const VkBufferCopy region{0, 0, upload_bytes};
      vkCmdCopyBuffer(cmd, rays_staging_.handle(), rays_.handle(), 1, &region);
    }
    const gpu::Counters zero{0, 1, 1, 0, 0, 0, 0};
    vkCmdUpdateBuffer(cmd, counters_.handle(), 0, sizeof(zero), &zero);
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    timestamps_->write(cmd, kStampUploaded);

    const uint64_t groups = (batch.ends.size() + gpu::kShootGroup - 1) / gpu::kShootGroup;
    for (uint64_t g = 0; g < groups; g += max_groups_) {
      sp.ray_base = uint32_t(g * gpu::kShootGroup);
      shoot.dispatch(cmd, &sp, uint32_t(std::min<uint64_t>(max_groups_, groups - g)));
    }
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
    timestamps_->write(cmd, kStampShot);
    compact_->dispatch_indirect(cmd, &cp, counters_.handle(), 0);
    record_counters_readback(cmd);
    timestamps_->write(cmd, kStampCompacted);
    runner_->submit_and_wait();
    const double wall_ms = ms_since(t_submit);

    // Split the submission's wall time by the device's clock: the copy is upload, the
    // compact pass is compaction, the rest (the shoot pass and submission overhead) shoot.
    timestamps_->fetch(kStampCount);
    const double gpu_upload = timestamps_->elapsed_ms(kStampStart, kStampUploaded);
    const double gpu_compact = timestamps_->elapsed_ms(kStampShot, kStampCompacted);
    stats.times.upload_ms += gpu_upload;
    stats.times.compact_ms += gpu_compact;
    stats.times.shoot_ms += std::max(0.0, wall_ms - gpu_upload - gpu_compact);

    const auto t_read = Clock::now();
    const gpu::Counters first = read_counters();
    if (first.walk_overruns) {
      std::cerr << "octomap-rt vulkan: " << first.walk_overruns << " ray walks hit the step guard\n";
    }
    const uint32_t touched = first.touched_count;
    uint64_t compacted = first.words_compacted;
    read_back(first.emitted_count, out);

    // Rare: more touched words than one compact pass can emit into the output buffer.
    for (uint64_t begin = sizing_.chunk_words; begin < touched; begin += sizing_.chunk_words) {
      cp.chunk_begin = uint32_t(begin);
      const uint32_t words = uint32_t(std::min<uint64_t>(sizing_.chunk_words, touched - begin));
      cmd = runner_->begin();
      vkCmdFillBuffer(cmd, counters_.handle(), gpu::kEmittedOffset, sizeof(uint32_t), 0);
      vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
      compact_->dispatch(cmd, &cp, (words + gpu::kCompactGroup - 1) / gpu::kCompactGroup);
      record_counters_readback(cmd);
      runner_->submit_and_wait();
      const gpu::Counters& c = read_counters();
      compacted = c.words_compacted;
      read_back(c.emitted_count, out);
    }
    stats.times.compact_ms += ms_since(t_read);
    stats.words_touched += touched;
    stats.words_read_back += compacted;
  }

  // Appends the first `count` voxels of the output buffer to `out`.
  void read_back(uint32_t count, VoxelList& out) {
    if (count == 0) return;
    if (count > sizing_.output_voxels) throw std::logic_error("vulkan back end: voxel output overflowed");
    const size_t bytes = size_t(count) * sizeof(VoxelUpdate);
    if (!unified_) {
      VkCommandBuffer cmd = runner_->begin();
      const VkBufferCopy region{0, 0, bytes};
      vkCmdCopyBuffer(cmd, voxels_.handle(), voxels_readback_.handle(), 1, &region);
      vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                         VK_ACCESS_HOST_READ_BIT);
      runner_->submit_and_wait();
    }
    const vk::Buffer& src = unified_ ? voxels_ : voxels_readback_;
    src.invalidate();
    const size_t old = out.size();
    out.resize(old + count);
    std::memcpy(out.data() + old, src.mapped(), bytes);
  }

  // Declared first: destroyed last, after every buffer and pipeline made from it.
  std::unique_ptr<vk::Context> ctx_;
  bool unified_ = false;
  uint32_t max_groups_ = 65535;
  gpu::RaySpaceSizing sizing_;
  uint64_t grid_allocations_ = 0;
  uint64_t ray_capacity_ = 0;
  std::string name_;
  vk::Buffer grid_, touched_, counters_, voxels_;
  vk::Buffer counters_readback_, voxels_readback_;  // discrete GPUs only
  vk::Buffer rays_staging_, rays_;                  // rays_staging_: discrete GPUs only
  std::unique_ptr<vk::ComputePipeline> shoot_octomap_, shoot_exact_, compact_;
  std::unique_ptr<vk::CommandRunner> runner_;
  std::unique_ptr<vk::TimestampQueries> timestamps_;
};

}  // namespace

std::unique_ptr<RayBackend> make_vulkan_backend(const BackendOptions& opts, const VulkanTuning& tuning,
                                                std::string* log) {
  return std::make_unique<VulkanBackend>(opts, tuning, log);
}

std::unique_ptr<RayBackend> make_vulkan_backend(const BackendOptions& opts, std::string* log) {
  return make_vulkan_backend(opts, VulkanTuning{}, log);
}

}  // namespace ort
