// The `vulkan` back end: compute shaders shooting into the GPU ray space
// (gpu/gpu_ray_space.h), which owns the grid, the touched list, compaction and readback.
// This file holds only the shooting pass: one invocation per ray (shoot_octomap.comp or
// shoot_exact.comp), split into dispatches of at most maxComputeWorkGroupCount groups, over
// key-aligned windows cut to the grid's capacity (core window planning, plan_windows).
// With BackendOptions::gpu_prepare it also prepares scans on the device (gpu/gpu_prepare.h):
// the rays never exist on the host.
#include "gpu/vulkan_backend.h"

#include <algorithm>
#include <chrono>
#include <memory>
#include <stdexcept>

#include "core/clock.h"
#include "core/ray_space.h"
#include "gpu/gpu_prepare.h"
#include "gpu/gpu_ray_space.h"
#include "gpu/ray_space_sizing.h"
#include "gpu/shader_interface.h"
#include "gpu/vk/vk_context.h"
#include "gpu/vk/vk_pipeline.h"
#include "shaders/shoot_exact_spv.h"
#include "shaders/shoot_octomap_spv.h"

namespace ort {
namespace {

constexpr int kWindowMargin = 2;  // voxels around the key box: the walk may overstep by one

std::shared_ptr<vk::Context> make_context(const BackendOptions& opts) {
  vk::ContextOptions co;
  co.device = opts.device;
  co.need_float64 = true;  // OctoMap's tMax/tDelta are doubles
  return std::make_shared<vk::Context>(co);
}

// The ray space: a max range sizes it (the cube any scan fits in), a budget given fixes it;
// otherwise it is sized from the scans, starting small and growing up to the automatic budget.
gpu::GpuRaySpaceOptions ray_space_for(const vk::Context& ctx, const BackendOptions& opts, const VulkanTuning& tuning) {
  const VkPhysicalDeviceLimits& limits = ctx.properties().limits;
  const uint64_t budget = opts.grid_budget_bytes
                              ? opts.grid_budget_bytes
                              : gpu::auto_grid_budget(limits.maxStorageBufferRange, ctx.device_local_bytes());
  gpu::GpuRaySpaceOptions o;
  o.voxels_in_host_memory = opts.compact_into_host_memory;
  o.sizing = gpu::size_ray_space(opts.max_range, opts.resolution, budget, limits.maxStorageBufferRange,
                                 limits.maxComputeWorkGroupCount[0], tuning.output_voxels);
  const uint64_t start = tuning.start_grid_words ? tuning.start_grid_words : gpu::kStartGridWords;
  if (opts.grid_budget_bytes == 0 && opts.max_range < 0 && o.sizing.grid_words > start) {
    o.max_grid_words = o.sizing.grid_words;
    o.grow_to = [max_buffer = uint64_t(limits.maxStorageBufferRange), groups = limits.maxComputeWorkGroupCount[0],
                 output = tuning.output_voxels](uint64_t words) {
      return gpu::ray_space_of_words(words, max_buffer, groups, output);
    };
    o.sizing = o.grow_to(start);
  }
  return o;
}

// A scan's ray space as its windows will be planned: the key box widened by the margin.
uint64_t widened_voxels(const KeyBox& keys, int margin) {
  if (keys.empty()) return 0;
  uint64_t v = 1;
  for (int i = 0; i < 3; ++i) v *= uint64_t(keys.hi[i] - keys.lo[i] + 1 + 2 * margin);
  return v;
}

class VulkanBackend final : public RayBackend {
 public:
  VulkanBackend(const BackendOptions& opts, const VulkanTuning& tuning, const Log& log)
      : ctx_(make_context(opts)),
        space_(ctx_, ray_space_for(*ctx_, opts, tuning)),
        shoot_octomap_(*ctx_, shoot_octomap_spv, 4, sizeof(gpu::ShootPush)),
        shoot_exact_(*ctx_, shoot_exact_spv, 4, sizeof(gpu::ShootPush)),
        max_groups_(ctx_->properties().limits.maxComputeWorkGroupCount[0]),
        resolution_(opts.resolution),
        log_(log) {
    if (opts.gpu_prepare) prepare_ = std::make_unique<gpu::GpuPrepare>(ctx_);
    space_.on_shoot_buffers([this](const gpu::ShootBuffers& b) {
      for (vk::ComputePipeline* p : {&shoot_octomap_, &shoot_exact_}) {
        p->bind_buffers({b.rays, b.grid, b.touched, b.counters});
      }
    });
    name_ = ctx_->device_name() + " (" + vk::device_type_name(ctx_->properties().deviceType) + ")";
    const uint64_t words = space_.sizing().grid_words;
    log.info("vulkan: " + name_ + ", grid " + std::to_string((words * 4 + 1023) >> 10) + " KiB (" +
             std::to_string(space_.grid_voxels()) + " voxels" +
             (space_.can_grow()
                  ? ", grows with the scans up to " + std::to_string(space_.max_grid_words() >> 18) + " MiB"
                  : std::string()) +
             "), " + (ctx_->unified_memory() ? "unified memory" : "device-local memory with staging"));
  }

  BackendKind kind() const override { return BackendKind::kVulkan; }
  std::string device_name() const override { return name_; }

  void shoot(const RayBatch& batch, Traversal mode, VoxelList& out, ShootStats& stats) override {
    const vk::ComputePipeline& pass = mode == Traversal::kOctomap ? shoot_octomap_ : shoot_exact_;
    fit_ray_space(batch.keys);
    const std::vector<KeyBox> windows = plan_windows(batch.keys, space_.grid_voxels(), kWindowMargin);
    space_.shoot(
        batch, windows, [&](VkCommandBuffer cmd, gpu::ShootPush push) { record_shoot(cmd, pass, push); }, out, stats);
  }

  bool prepares_on_device() const override { return prepare_ != nullptr; }

  void shoot_posed(const PosedPoints& scan, Traversal mode, VoxelList& out, ShootStats& stats,
                   PrepareReport& report) override {
    if (!prepare_) return RayBackend::shoot_posed(scan, mode, out, stats, report);  // CPU preparation
    out.clear();
    const size_t points = scan.point_count();
    report.points_in += points;
    RayBatch header;  // origin, origin key, key box; the ends stay on the device
    if (!prepare_origin(scan.origin, resolution_, header, report)) return;
    const auto t_stage = SteadyClock::now();
    prepare_->stage_points(scan.xyz);
    stats.times.upload_ms += ms_since(t_stage);
    const auto t_prepare = SteadyClock::now();
    const VkBuffer rays = space_.device_rays(points);
    const gpu::DevicePrepared p = prepare_->run({*scan.pose, header.origin, scan.max_range, resolution_}, rays);
    stats.times.prepare_ms += ms_since(t_prepare);
    report.nonfinite += p.nonfinite;
    report.out_of_range += p.out_of_range;
    report.cut_at_max_range += p.cut_at_max_range;
    report.degenerate += p.degenerate;
    report.read_as_zero += p.read_as_zero;
    const uint64_t kept = points - p.nonfinite - p.out_of_range - p.degenerate;
    report.rays += kept;
    if (kept == 0) return;  // as prepare_scan: no rays, nothing shot
    header.keys.include(octomap::OcTreeKey(p.end_keys.lo[0], p.end_keys.lo[1], p.end_keys.lo[2]));
    header.keys.include(octomap::OcTreeKey(p.end_keys.hi[0], p.end_keys.hi[1], p.end_keys.hi[2]));
    if (over_device_bounds(header.keys, kept, scan)) {
      report.device_declined = true;  // far-flung: the engine tiles it along its rays on the CPU path
      return;
    }
    const vk::ComputePipeline& pass = mode == Traversal::kOctomap ? shoot_octomap_ : shoot_exact_;
    fit_ray_space(header.keys);
    const std::vector<KeyBox> windows = plan_windows(header.keys, space_.grid_voxels(), kWindowMargin);
    space_.shoot_resident(
        header, uint32_t(points), windows,
        [&](VkCommandBuffer cmd, gpu::ShootPush push) { record_shoot(cmd, pass, push); }, out, stats);
  }

 private:
  void fit_ray_space(const KeyBox& keys) {
    const uint64_t voxels = widened_voxels(keys, kWindowMargin);
    if (space_.fit(voxels))
      log_.info("vulkan: ray space grown to " + std::to_string((space_.sizing().grid_words * 4 + 1023) >> 10) +
                " KiB for a scan of " + std::to_string(voxels) + " voxels");
  }

  // PosedPoints' bounds: the key box widened by the window margin, and a walk bound (no ray
  // of the scan visits more keys than the box's extents summed, plus one).
  static bool over_device_bounds(const KeyBox& keys, uint64_t rays, const PosedPoints& scan) {
    uint64_t box = 1, extents = 1;
    for (int i = 0; i < 3; ++i) {
      const uint64_t side = uint64_t(keys.hi[i] - keys.lo[i]) + 1;
      box *= side + 2 * uint64_t(kWindowMargin);
      extents += side;
    }
    return (scan.max_box_voxels && box > scan.max_box_voxels) ||
           (scan.max_walk_keys && rays * extents > scan.max_walk_keys);
  }

  // One invocation per ray, in dispatches of at most max_groups_ groups.
  void record_shoot(VkCommandBuffer cmd, const vk::ComputePipeline& pass, gpu::ShootPush push) const {
    const uint64_t groups = (uint64_t(push.ray_count) + gpu::kShootGroup - 1) / gpu::kShootGroup;
    for (uint64_t g = 0; g < groups; g += max_groups_) {
      push.ray_base = uint32_t(g * gpu::kShootGroup);
      pass.dispatch(cmd, &push, uint32_t(std::min<uint64_t>(max_groups_, groups - g)));
    }
  }

  // Declared first: destroyed last (the ray space and the pipelines share it).
  std::shared_ptr<vk::Context> ctx_;
  gpu::GpuRaySpace space_;
  vk::ComputePipeline shoot_octomap_, shoot_exact_;
  uint32_t max_groups_;
  double resolution_;
  Log log_;
  std::unique_ptr<gpu::GpuPrepare> prepare_;  // null without BackendOptions::gpu_prepare
  std::string name_;
};

}  // namespace

std::unique_ptr<RayBackend> make_vulkan_backend(const BackendOptions& opts, const Log& log) {
  return make_vulkan_backend(opts, VulkanTuning{}, log);
}

std::unique_ptr<RayBackend> make_vulkan_backend(const BackendOptions& opts, const VulkanTuning& tuning,
                                                const Log& log) {
  return std::make_unique<VulkanBackend>(opts, tuning, log);
}

}  // namespace ort
