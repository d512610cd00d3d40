#include "gpu/gpu_prepare.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "core/prepare_scan.h"
#include "gpu/shader_interface.h"
#include "shaders/prepare_rays_spv.h"

namespace ort::gpu {
namespace {

static_assert(sizeof(octomap::point3d) == 12, "points are uploaded as they lie in memory: 3 floats");

constexpr uint64_t kMinPointCapacity = 1 << 16;
constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
constexpr VkMemoryPropertyFlags kHostCoherent =
    VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
constexpr VkMemoryPropertyFlags kHostCached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;

// OctoMap's test: Vector3::norm() (sqrt in double of the float |d|^2) <= max_range.
bool within(float norm_sq, double max_range) { return std::sqrt(double(norm_sq)) <= max_range; }

PreparePush prepare_push(const ScanFrame& f, uint32_t point_count) {
  PreparePush p{};
  p.resolution_factor = 1.0 / f.resolution;  // as OctoMap keeps it
  const octomath::Quaternion& q = f.pose.rot();
  p.rot[0] = q.u();
  p.rot[1] = q.x();
  p.rot[2] = q.y();
  p.rot[3] = q.z();
  for (int i = 0; i < 3; ++i) {
    p.trans[i] = f.pose.trans()(i);
    p.origin[i] = read_tiny_as_zero(f.origin(i));  // as prepare_origin reads it
  }
  p.point_count = point_count;
  p.has_max_range = f.max_range < 0.0 ? 0u : 1u;
  p.norm_sq_limit = p.has_max_range ? norm_sq_limit(f.max_range) : 0.0f;
  p.max_range_f = float(f.max_range);  // computeUpdate's (float)maxrange
  p.zero = 0.0f;
  p.tiny_coordinate = kTinyCoordinate;
  p.min_ray_length = kMinRayLength;
  return p;
}

}  // namespace

// |d|^2 >= 0 is a float, and the test is monotone in it: binary search over the bit
// patterns of the non-negative floats (ordered as integers), +inf included.
float norm_sq_limit(double max_range) {
  uint32_t lo = 0, hi = 0x7f800000u;  // 0.0f .. +inf
  auto as_float = [](uint32_t bits) {
    float f;
    std::memcpy(&f, &bits, sizeof f);
    return f;
  };
  if (!within(as_float(lo), max_range)) return -1.0f;
  if (within(as_float(hi), max_range)) return as_float(hi);
  while (hi - lo > 1) {  // within(lo) && !within(hi)
    const uint32_t mid = lo + (hi - lo) / 2;
    (within(as_float(mid), max_range) ? lo : hi) = mid;
  }
  return as_float(lo);
}

GpuPrepare::GpuPrepare(std::shared_ptr<const vk::Context> ctx)
    : ctx_(std::move(ctx)),
      unified_(ctx_->unified_memory()),
      runner_(*ctx_),
      pass_(*ctx_, prepare_rays_spv, 3, sizeof(PreparePush)),
      max_groups_(ctx_->properties().limits.maxComputeWorkGroupCount[0]) {
  if (unified_) {
    result_ = vk::Buffer(*ctx_, sizeof(PrepareCounts), kStorage, kHostCoherent, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  } else {
    result_ = vk::Buffer(*ctx_, sizeof(PrepareCounts), kStorage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    result_readback_ =
        vk::Buffer(*ctx_, sizeof(PrepareCounts), kStorage, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, kHostCached);
  }
  ensure_point_capacity(kMinPointCapacity);
}

// The points buffers only grow (geometrically), like the rays buffer.
void GpuPrepare::ensure_point_capacity(uint64_t points) {
  if (points <= point_capacity_) return;
  const uint64_t capacity = std::max({points, 2 * point_capacity_, kMinPointCapacity});
  const VkDeviceSize bytes = capacity * sizeof(octomap::point3d);
  if (unified_) {
    points_ = vk::Buffer(*ctx_, bytes, kStorage, kHostCoherent, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  } else {
    points_staging_ = vk::Buffer(*ctx_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, kHostCoherent);
    points_ = vk::Buffer(*ctx_, bytes, kStorage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  }
  point_capacity_ = capacity;
  bound_ = false;
}

void GpuPrepare::stage_points(std::span<const float> sensor_xyz) {
  const uint64_t points = sensor_xyz.size() / 3;
  if (points > UINT32_MAX) throw std::runtime_error("GPU preparation: more than 2^32 points in one scan");
  ensure_point_capacity(points);
  const vk::Buffer& host = unified_ ? points_ : points_staging_;
  if (points) std::memcpy(host.mapped(), sensor_xyz.data(), points * sizeof(octomap::point3d));
  host.flush();
  staged_points_ = points;
}

void GpuPrepare::bind(VkBuffer rays) {
  if (bound_ && rays == bound_rays_) return;
  pass_.bind_buffers({points_.handle(), rays, result_.handle()});
  bound_rays_ = rays;
  bound_ = true;
}

DevicePrepared GpuPrepare::run(const ScanFrame& frame, VkBuffer rays) {
  DevicePrepared out;
  if (staged_points_ == 0) return out;
  bind(rays);
  record(runner_.begin(), frame);
  runner_.submit_and_wait();
  const vk::Buffer& r = unified_ ? result_ : result_readback_;
  r.invalidate();
  const PrepareCounts& c = *r.as<PrepareCounts>();
  if (c.key_lo[0] != ~0u) {
    out.end_keys.include(octomap::OcTreeKey(c.key_lo[0], c.key_lo[1], c.key_lo[2]));
    out.end_keys.include(octomap::OcTreeKey(c.key_hi[0], c.key_hi[1], c.key_hi[2]));
  }
  out.nonfinite = c.nonfinite;
  out.out_of_range = c.out_of_range;
  out.cut_at_max_range = c.cut_at_max_range;
  out.degenerate = c.degenerate;
  out.read_as_zero = c.read_as_zero;
  return out;
}

// [points copy] -> result reset -> the pass, in dispatches of at most max_groups_ groups ->
// the result made visible to the host (through its mirror on discrete GPUs).
void GpuPrepare::record(VkCommandBuffer cmd, const ScanFrame& frame) {
  if (!unified_) {
    const VkBufferCopy region{0, 0, staged_points_ * sizeof(octomap::point3d)};
    vkCmdCopyBuffer(cmd, points_staging_.handle(), points_.handle(), 1, &region);
  }
  PrepareCounts reset{};
  std::fill(std::begin(reset.key_lo), std::end(reset.key_lo), ~0u);
  vkCmdUpdateBuffer(cmd, result_.handle(), 0, sizeof(reset), &reset);
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  PreparePush push = prepare_push(frame, uint32_t(staged_points_));
  const uint64_t groups = (staged_points_ + kPrepareGroup - 1) / kPrepareGroup;
  for (uint64_t g = 0; g < groups; g += max_groups_) {
    push.point_base = uint32_t(g * kPrepareGroup);
    pass_.dispatch(cmd, &push, uint32_t(std::min<uint64_t>(max_groups_, groups - g)));
  }
  // The rays, for the shooting passes of the submissions that follow.
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                     VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_SHADER_READ_BIT);
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                     VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                     VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT);
  if (unified_) return;
  const VkBufferCopy region{0, 0, sizeof(PrepareCounts)};
  vkCmdCopyBuffer(cmd, result_.handle(), result_readback_.handle(), 1, &region);
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                     VK_ACCESS_HOST_READ_BIT);
}

}  // namespace ort::gpu
