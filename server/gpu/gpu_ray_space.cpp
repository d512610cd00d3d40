#include "gpu/gpu_ray_space.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <utility>

#include "core/clock.h"
#include "gpu/vk/vk_check.h"
#include "shaders/compact_touched_spv.h"

namespace ort::gpu {
namespace {

constexpr uint64_t kMinRayCapacity = 1 << 16;
constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
constexpr VkMemoryPropertyFlags kHostCoherent =
    VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
constexpr VkMemoryPropertyFlags kHostCached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;

// Timestamp slots of one window's first submission.
enum Stamp : uint32_t { kStampStart, kStampUploaded, kStampShot, kStampCompacted, kStampCount };

// Transfer writes (counters reset, rays copy) visible to the shaders of `stage`.
void transfer_to_shaders(VkCommandBuffer cmd, VkPipelineStageFlags stage) {
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, stage,
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

ShootPush shoot_push(const RayBatch& batch, uint32_t ray_count, const KeyBox& w, uint32_t first_chunk_words) {
  ShootPush p{};
  p.resolution = batch.resolution;
  p.resolution_factor = 1.0 / batch.resolution;  // as OctoMap keeps it
  p.origin[0] = batch.origin.x();
  p.origin[1] = batch.origin.y();
  p.origin[2] = batch.origin.z();
  p.ray_count = ray_count;
  p.first_chunk_words = first_chunk_words;
  p.ray_base = 0;
  for (int i = 0; i < 3; ++i) {
    p.win_lo[i] = w.lo[i];
    p.win_n[i] = uint32_t(w.hi[i] - w.lo[i] + 1);
    p.origin_key[i] = batch.origin_key[i];
  }
  return p;
}

CompactPush compact_push(const KeyBox& w, uint32_t chunk_words) {
  CompactPush p{};
  for (int i = 0; i < 3; ++i) {
    p.win_lo[i] = w.lo[i];
    p.win_n[i] = uint32_t(w.hi[i] - w.lo[i] + 1);
  }
  p.chunk_begin = 0;
  p.chunk_words = chunk_words;
  return p;
}

}  // namespace

GpuRaySpace::GpuRaySpace(std::shared_ptr<const vk::Context> ctx, const GpuRaySpaceOptions& opts)
    : ctx_(std::move(ctx)),
      opts_(opts),
      unified_(ctx_->unified_memory()),
      runner_(*ctx_),
      stamps_(*ctx_, kStampCount),
      compact_(*ctx_, compact_touched_spv, 4, sizeof(CompactPush)) {
  make_buffers();
  compact_.bind_buffers({grid_.handle(), touched_.handle(), counters_.handle(), voxels_.handle()});
  ensure_ray_capacity(kMinRayCapacity);
  clear_grid();
}

// A new grid starts clear, once; from then on only compaction clears it.
void GpuRaySpace::clear_grid() {
  VkCommandBuffer cmd = runner_.begin();
  vkCmdFillBuffer(cmd, grid_.handle(), 0, VK_WHOLE_SIZE, 0);
  runner_.submit_and_wait();
}

// Between scans (every submission has been waited for), so no buffer replaced is in use.
bool GpuRaySpace::fit(uint64_t voxels) {
  const uint64_t have = opts_.sizing.grid_words;
  if (!opts_.grow_to || have >= opts_.max_grid_words || voxels <= grid_voxels()) return false;
  const uint64_t need = (voxels + kVoxelsPerWord - 1) / kVoxelsPerWord;
  opts_.sizing = opts_.grow_to(std::min(opts_.max_grid_words, std::max(need, 2 * have)));
  make_buffers();
  compact_.bind_buffers({grid_.handle(), touched_.handle(), counters_.handle(), voxels_.handle()});
  if (bind_shoot_buffers_) bind_shoot_buffers_(shoot_buffers());
  clear_grid();
  return true;
}

// Unified memory (lavapipe, integrated GPUs): everything host-visible, read and written in
// place. Discrete GPUs: device-local working buffers, host-visible mirrors to read back.
void GpuRaySpace::make_buffers() {
  const vk::Context& c = *ctx_;
  const RaySpaceSizing& s = opts_.sizing;
  const VkMemoryPropertyFlags required =
      unified_ ? kHostCoherent : VkMemoryPropertyFlags(VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  const VkMemoryPropertyFlags preferred = unified_ ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT : 0;
  grid_ = vk::Buffer(c, s.grid_words * 4, kStorage, required, preferred);
  ++grid_allocations_;
  touched_ = vk::Buffer(c, s.grid_words * 4, kStorage, required, preferred);  // a word is listed once a window
  counters_ = vk::Buffer(c, sizeof(Counters), kStorage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, required, preferred);
  const VkDeviceSize voxel_bytes = s.output_voxels * sizeof(VoxelUpdate);
  if (unified_) {
    voxels_ = vk::Buffer(c, voxel_bytes, kStorage, required, preferred);
    return;
  }
  counters_readback_ = vk::Buffer(c, sizeof(Counters), kStorage, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, kHostCached);
  if (opts_.voxels_in_host_memory) {
    voxels_ = vk::Buffer(c, voxel_bytes, kStorage, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, kHostCached);
  } else {
    voxels_ = vk::Buffer(c, voxel_bytes, kStorage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    voxels_readback_ = vk::Buffer(c, voxel_bytes, kStorage, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, kHostCached);
  }
}

ShootBuffers GpuRaySpace::shoot_buffers() const {
  return {rays_.handle(), grid_.handle(), touched_.handle(), counters_.handle()};
}

void GpuRaySpace::on_shoot_buffers(std::function<void(const ShootBuffers&)> bind) {
  bind_shoot_buffers_ = std::move(bind);
  if (bind_shoot_buffers_) bind_shoot_buffers_(shoot_buffers());
}

// The rays buffers only grow (geometrically), so a steady stream of scans allocates nothing.
void GpuRaySpace::ensure_ray_capacity(uint64_t rays) {
  if (rays <= ray_capacity_) return;
  const uint64_t capacity = std::max({rays, 2 * ray_capacity_, kMinRayCapacity});
  const VkDeviceSize bytes = capacity * sizeof(RayEnd);
  if (unified_) {
    rays_ = vk::Buffer(*ctx_, bytes, kStorage, kHostCoherent, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  } else {
    rays_staging_ = vk::Buffer(*ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, kHostCoherent);
    rays_ = vk::Buffer(*ctx_, bytes, kStorage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  }
  ray_capacity_ = capacity;
  if (bind_shoot_buffers_) bind_shoot_buffers_(shoot_buffers());
}

void GpuRaySpace::upload_rays(const RayBatch& batch, ShootStats& stats) {
  const auto t = SteadyClock::now();
  ensure_ray_capacity(batch.ends.size());
  const size_t bytes = batch.ends.size() * sizeof(RayEnd);
  const vk::Buffer& host = unified_ ? rays_ : rays_staging_;
  std::memcpy(host.mapped(), batch.ends.data(), bytes);
  host.flush();
  pending_ray_bytes_ = unified_ ? 0 : bytes;
  stats.times.upload_ms += ms_since(t);
}

void GpuRaySpace::shoot(const RayBatch& batch, std::span<const KeyBox> windows, const RecordShoot& record_shoot,
                        VoxelList& out, ShootStats& stats) {
  out.clear();
  if (batch.ends.empty()) {
    shoot_windows(batch, 0, {}, record_shoot, out, stats);
    return;
  }
  if (batch.ends.size() > UINT32_MAX) throw std::runtime_error("GPU ray space: more than 2^32 rays in one scan");
  upload_rays(batch, stats);
  shoot_windows(batch, uint32_t(batch.ends.size()), windows, record_shoot, out, stats);
}

VkBuffer GpuRaySpace::device_rays(uint64_t rays) {
  if (rays > UINT32_MAX) throw std::runtime_error("GPU ray space: more than 2^32 rays in one scan");
  ensure_ray_capacity(rays);
  return rays_.handle();
}

void GpuRaySpace::shoot_resident(const RayBatch& header, uint32_t ray_count, std::span<const KeyBox> windows,
                                 const RecordShoot& record_shoot, VoxelList& out, ShootStats& stats) {
  out.clear();
  if (ray_count > ray_capacity_) throw std::logic_error("GPU ray space: more resident rays than the rays buffer holds");
  pending_ray_bytes_ = 0;
  shoot_windows(header, ray_count, ray_count ? windows : std::span<const KeyBox>{}, record_shoot, out, stats);
}

void GpuRaySpace::shoot_windows(const RayBatch& batch, uint32_t ray_count, std::span<const KeyBox> windows,
                                const RecordShoot& record_shoot, VoxelList& out, ShootStats& stats) {
  stats.grid_words = opts_.sizing.grid_words;
  stats.grid_allocations = grid_allocations_;  // the grid, touched list and output: at start-up and as fit() grows them
  for (const KeyBox& w : windows) {
    if (w.voxel_count() > grid_voxels()) throw std::logic_error("GPU ray space: a window larger than the grid");
    shoot_window(batch, ray_count, w, record_shoot, out, stats);
  }
  stats.windows += windows.size();
}

void GpuRaySpace::shoot_window(const RayBatch& batch, uint32_t ray_count, const KeyBox& window,
                               const RecordShoot& record_shoot, VoxelList& out, ShootStats& stats) {
  const CompactPush cp = compact_push(window, opts_.sizing.chunk_words);
  const auto t_submit = SteadyClock::now();
  VkCommandBuffer cmd = runner_.begin();
  record_first_pass(cmd, shoot_push(batch, ray_count, window, opts_.sizing.chunk_words), record_shoot, cp);
  runner_.submit_and_wait();
  const double wall_ms = ms_since(t_submit);

  // Split the submission's wall time by the device's clock: the copy is upload, the
  // compaction is compaction, the rest (the shooting pass and submission overhead) shoot.
  stamps_.fetch(kStampCount);
  const double gpu_upload = stamps_.elapsed_ms(kStampStart, kStampUploaded);
  const double gpu_compact = stamps_.elapsed_ms(kStampShot, kStampCompacted);
  stats.times.shoot_gpu_ms += stamps_.elapsed_ms(kStampUploaded, kStampShot);
  stats.times.upload_ms += gpu_upload;
  stats.times.compact_ms += gpu_compact;
  stats.times.compact_gpu_ms += gpu_compact;
  stats.times.shoot_ms += std::max(0.0, wall_ms - gpu_upload - gpu_compact);

  const auto t_read = SteadyClock::now();
  const Counters first = read_counters();
  stats.walk_overruns += first.walk_overruns;  // reported by the engine's callers; must stay 0
  read_voxels(first.emitted_count, out, stats.times);
  const uint64_t compacted = compact_rest(cp, first, out, stats.times);
  stats.times.compact_ms += ms_since(t_read);
  stats.words_touched += first.touched_count;
  stats.words_read_back += compacted;
}

void GpuRaySpace::record_first_pass(VkCommandBuffer cmd, const ShootPush& push, const RecordShoot& record_shoot,
                                    const CompactPush& cp) {
  stamps_.reset(cmd);
  stamps_.write(cmd, kStampStart, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
  if (pending_ray_bytes_) {
    const VkBufferCopy region{0, 0, pending_ray_bytes_};
    vkCmdCopyBuffer(cmd, rays_staging_.handle(), rays_.handle(), 1, &region);
    pending_ray_bytes_ = 0;
  }
  const Counters zero{0, 1, 1, 0, 0, 0, 0};  // dispatch_x counts up as words are listed
  vkCmdUpdateBuffer(cmd, counters_.handle(), 0, sizeof(zero), &zero);
  transfer_to_shaders(cmd, opts_.shoot_stage);
  stamps_.write(cmd, kStampUploaded);

  record_shoot(cmd, push);
  vk::memory_barrier(cmd, opts_.shoot_stage, VK_ACCESS_SHADER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
  stamps_.write(cmd, kStampShot);
  compact_.dispatch_indirect(cmd, &cp, counters_.handle(), 0);
  record_counters_readback(cmd);
  stamps_.write(cmd, kStampCompacted);
}

// Rare: more touched words than one compaction can emit into the output. Returns the words
// compacted in this window, as the counters count them.
uint64_t GpuRaySpace::compact_rest(CompactPush cp, const Counters& first, VoxelList& out, StageTimes& times) {
  const uint32_t touched = first.touched_count;
  uint64_t compacted = first.words_compacted;
  for (uint64_t begin = cp.chunk_words; begin < touched; begin += cp.chunk_words) {
    const uint32_t words = uint32_t(std::min<uint64_t>(cp.chunk_words, touched - begin));
    cp.chunk_begin = uint32_t(begin);
    VkCommandBuffer cmd = runner_.begin();
    vkCmdFillBuffer(cmd, counters_.handle(), kEmittedOffset, sizeof(uint32_t), 0);
    transfer_to_shaders(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
    compact_.dispatch(cmd, &cp, (words + kCompactGroup - 1) / kCompactGroup);
    record_counters_readback(cmd);
    runner_.submit_and_wait();
    const Counters& c = read_counters();
    compacted = c.words_compacted;
    read_voxels(c.emitted_count, out, times);
  }
  return compacted;
}

// Compaction's writes made visible to the host, through the host-visible mirror on discrete
// GPUs, at the end of a submission.
void GpuRaySpace::record_counters_readback(VkCommandBuffer cmd) {
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                     VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                     VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT);
  if (unified_) return;
  const VkBufferCopy region{0, 0, sizeof(Counters)};
  vkCmdCopyBuffer(cmd, counters_.handle(), counters_readback_.handle(), 1, &region);
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                     VK_ACCESS_HOST_READ_BIT);
}

const Counters& GpuRaySpace::read_counters() const {
  const vk::Buffer& b = unified_ ? counters_ : counters_readback_;
  b.invalidate();
  return *b.as<Counters>();
}

// Appends the first `count` voxels of the output to `out`.
void GpuRaySpace::read_voxels(uint32_t count, VoxelList& out, StageTimes& times) {
  if (count == 0) return;
  if (count > opts_.sizing.output_voxels) throw std::logic_error("GPU ray space: the voxel output overflowed");
  const size_t bytes = size_t(count) * sizeof(VoxelUpdate);
  const auto t_copy = SteadyClock::now();
  if (voxels_readback_) {
    VkCommandBuffer cmd = runner_.begin();
    const VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cmd, voxels_.handle(), voxels_readback_.handle(), 1, &region);
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                       VK_ACCESS_HOST_READ_BIT);
    runner_.submit_and_wait();
  }
  const auto t_unpack = SteadyClock::now();
  times.readback_copy_ms += ms_between(t_copy, t_unpack);
  const vk::Buffer& src = voxels_readback_ ? voxels_readback_ : voxels_;
  src.invalidate();
  // Room for this list and a quarter more: the caller keeps the list's storage from scan to
  // scan (ShotScan::reset), and a scan only a little longer than the last would otherwise
  // move to fresh memory, where every 4 KiB page of a large list faults on first touch.
  const size_t need = out.size() + count;
  if (need > out.capacity()) out.reserve(need + need / 4);
  // Appended without value-initialising first (resize would write every byte twice).
  const VoxelUpdate* voxels = src.as<VoxelUpdate>();
  out.insert(out.end(), voxels, voxels + count);
  times.unpack_ms += ms_since(t_unpack);
}

}  // namespace ort::gpu
