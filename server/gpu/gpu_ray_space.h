// The GPU ray space: the paper's shared ray space on a Vulkan device, the one both GPU back
// ends (vulkan compute, rt) shoot into. It owns one persistent grid of 2-bit voxel states
// (01 occupied, 10 free, 11 -> occupied), the list of words touched in the current window,
// the counters, the voxel output, and the rays of the current scan; a back end brings only
// the commands of its own shooting pass.
//
// Per scan, shoot() puts the rays where the shaders read them (on discrete GPUs through a
// staging buffer; both only ever grow), then records one submission per window:
//   [rays copy, first window only] -> zero counters -> the back end's shooting pass (marks:
//   atomicOr of 2-bit states, the first touch of a word lists it) -> compaction (indirect
//   dispatch over the touched list: emit (key, state), clear the word) -> counters readback
// and reads the emitted count and exactly that many voxels; a touched list longer than one
// compaction chunk is compacted in further submissions. Nothing is sized per scan, nothing
// scales with the window: the grid is cleared through the touched list.
//
// Buffers and push constants: shaders/ray_space.glsl, mirrored in gpu/shader_interface.h.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>

#include <vulkan/vulkan.h>

#include "core/ray_backend.h"
#include "core/ray_batch.h"
#include "core/voxel_update.h"
#include "gpu/ray_space_sizing.h"
#include "gpu/shader_interface.h"
#include "gpu/vk/vk_buffer.h"
#include "gpu/vk/vk_commands.h"
#include "gpu/vk/vk_context.h"
#include "gpu/vk/vk_pipeline.h"
#include "gpu/vk/vk_timestamps.h"

namespace ort::gpu {

struct GpuRaySpaceOptions {
  RaySpaceSizing sizing;
  // The stage whose shaders mark the grid (compute, or ray tracing): the barriers before and
  // after the shooting pass name it.
  VkPipelineStageFlags shoot_stage = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT;
  // Discrete GPUs only: compaction writes the voxels straight into host-visible (cached)
  // memory, instead of device-local memory copied back in a submission of its own per
  // chunk. (The rt back end's choice; on unified memory everything is host-visible anyway.)
  bool voxels_in_host_memory = false;
  // A grid sized from the scans: fit() grows it up to `max_grid_words` (0: never), each time
  // to `grow_to(words)`'s sizing.
  uint64_t max_grid_words = 0;
  std::function<RaySpaceSizing(uint64_t words)> grow_to;
};

// The storage buffers of shaders/ray_space.glsl, bindings 0..3.
struct ShootBuffers {
  VkBuffer rays, grid, touched, counters;
};

// Records a back end's shooting pass into `cmd`. `push` describes the scan and the window;
// the callee may change its copy (ray_base, when it splits the dispatch).
using RecordShoot = std::function<void(VkCommandBuffer cmd, ShootPush push)>;

class GpuRaySpace {
 public:
  // Holds `ctx` for as long as it lives: the context (device) outlives every buffer here.
  GpuRaySpace(std::shared_ptr<const vk::Context> ctx, const GpuRaySpaceOptions& opts);
  GpuRaySpace(const GpuRaySpace&) = delete;
  GpuRaySpace& operator=(const GpuRaySpace&) = delete;

  const RaySpaceSizing& sizing() const { return opts_.sizing; }
  uint64_t grid_voxels() const { return opts_.sizing.grid_words * kVoxelsPerWord; }

  // A ray space of `voxels` (a scan's window before it is planned) fits in one window: grows
  // the grid to it (at least doubling, at most max_grid_words) when it can. True when it grew.
  bool fit(uint64_t voxels);
  bool can_grow() const { return opts_.grow_to && opts_.max_grid_words > opts_.sizing.grid_words; }
  uint64_t max_grid_words() const { return opts_.max_grid_words; }

  // `bind` gets the shooting pass's buffers now and again whenever one is re-created (the
  // rays buffer or the grid grows), always between submissions.
  void on_shoot_buffers(std::function<void(const ShootBuffers&)> bind);

  // One scan through `windows` (disjoint key boxes of at most grid_voxels() voxels each, in
  // the shapes the back end's pass needs). Clears `out`; adds to `stats`.
  void shoot(const RayBatch& batch, std::span<const KeyBox> windows, const RecordShoot& record_shoot, VoxelList& out,
             ShootStats& stats);

  // Rays written on the device (GPU preparation, gpu/gpu_prepare.h) instead of uploaded:
  // device_rays() makes room for `rays` and returns the buffer to write them into (valid
  // until the next call); shoot_resident() then shoots its first `ray_count` rays, with the
  // origin, origin key and resolution of `header` (whose ends are not read).
  VkBuffer device_rays(uint64_t rays);
  void shoot_resident(const RayBatch& header, uint32_t ray_count, std::span<const KeyBox> windows,
                      const RecordShoot& record_shoot, VoxelList& out, ShootStats& stats);

 private:
  void make_buffers();
  void clear_grid();
  void upload_rays(const RayBatch& batch, ShootStats& stats);
  void ensure_ray_capacity(uint64_t rays);
  void shoot_windows(const RayBatch& batch, uint32_t ray_count, std::span<const KeyBox> windows,
                     const RecordShoot& record_shoot, VoxelList& out, ShootStats& stats);
  void shoot_window(const RayBatch& batch, uint32_t ray_count, const KeyBox& window, const RecordShoot& record_shoot,
                    VoxelList& out, ShootStats& stats);
  void record_first_pass(VkCommandBuffer cmd, const ShootPush& push, const RecordShoot& record_shoot,
                         const CompactPush& cp);
  uint64_t compact_rest(CompactPush cp, const Counters& first, VoxelList& out, StageTimes& times);
  void record_counters_readback(VkCommandBuffer cmd);
  const Counters& read_counters() const;
  void read_voxels(uint32_t count, VoxelList& out, StageTimes& times);
  ShootBuffers shoot_buffers() const;

  // Declared first: destroyed last, after every buffer and pipeline made from it.
  std::shared_ptr<const vk::Context> ctx_;
  GpuRaySpaceOptions opts_;
  bool unified_ = false;
  vk::CommandRunner runner_;
  vk::TimestampQueries stamps_;
  vk::ComputePipeline compact_;
  vk::Buffer grid_, touched_, counters_, voxels_;
  vk::Buffer counters_readback_, voxels_readback_;  // discrete GPUs only
  vk::Buffer rays_staging_, rays_;                  // rays_staging_: discrete GPUs only
  uint64_t grid_allocations_ = 0;
  uint64_t ray_capacity_ = 0;
  VkDeviceSize pending_ray_bytes_ = 0;  // staged rays the next window's submission copies up
  std::function<void(const ShootBuffers&)> bind_shoot_buffers_;
};

}  // namespace ort::gpu
