#include "gpu/distance_transform.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <stdexcept>

#include "core/clock.h"
#include "shaders/edt_envelope_spv.h"
#include "shaders/edt_rows_spv.h"

namespace ort::gpu {
namespace {

// Mirrors edt_lines.glsl's LinePush.
struct LinePush {
  uint32_t n, lines, stride, div, mul;
};
constexpr uint32_t kGroup = 64;          // local_size_x of edt_lines.glsl
constexpr uint32_t kMaxGroupsX = 65535;  // a dispatch's x is split into x * y beyond this
constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
constexpr VkMemoryPropertyFlags kHostCoherent =
    VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;

vk::ContextOptions options(const std::string& device) {
  vk::ContextOptions o;
  o.device = device;
  o.need_float64 = false;
  return o;
}

void dispatch_lines(const vk::ComputePipeline& p, VkCommandBuffer cmd, const LinePush& push) {
  const uint32_t groups = (push.lines + kGroup - 1) / kGroup;
  const uint32_t gx = std::min(groups, kMaxGroupsX), gy = (groups + gx - 1) / gx;
  p.dispatch(cmd, &push, gx, gy);
}

}  // namespace

DistanceTransform::DistanceTransform(const std::string& device)
    : ctx_(std::make_shared<vk::Context>(options(device))),
      unified_(ctx_->unified_memory()),
      runner_(*ctx_),
      rows_(*ctx_, edt_rows_spv, 2, sizeof(LinePush)),
      envelope_(*ctx_, edt_envelope_spv, 4, sizeof(LinePush)) {}

DistanceTransform::~DistanceTransform() = default;

// Unified memory (lavapipe, integrated GPUs): all buffers host-visible, used in place.
// Discrete GPUs: device-local working buffers, a host-visible upload and read-back.
void DistanceTransform::ensure_capacity(uint64_t cells) {
  if (cells <= capacity_) return;
  const uint64_t c = std::max<uint64_t>(cells, capacity_ + capacity_ / 2);
  const VkDeviceSize occ_bytes = (c + 3) / 4 * 4, word_bytes = c * 4;
  const VkMemoryPropertyFlags required =
      unified_ ? kHostCoherent : VkMemoryPropertyFlags(VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  const VkMemoryPropertyFlags preferred = unified_ ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT : 0;
  occupied_ = vk::Buffer(*ctx_, occ_bytes, kStorage, required, preferred);
  squared_ = vk::Buffer(*ctx_, word_bytes, kStorage, required, preferred);
  sites_ = vk::Buffer(*ctx_, word_bytes, kStorage, required, preferred);
  starts_ = vk::Buffer(*ctx_, word_bytes, kStorage, required, preferred);
  values_ = vk::Buffer(*ctx_, word_bytes, kStorage, required, preferred);
  if (!unified_) {
    upload_ = vk::Buffer(*ctx_, occ_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, kHostCoherent);
    readback_ = vk::Buffer(*ctx_, word_bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                           VK_MEMORY_PROPERTY_HOST_CACHED_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  }
  rows_.bind_buffers({occupied_.handle(), squared_.handle()});
  envelope_.bind_buffers({squared_.handle(), sites_.handle(), starts_.handle(), values_.handle()});
  capacity_ = c;
}

void DistanceTransform::run(std::span<const uint8_t> occupied, int nx, int ny, int nz, std::span<uint32_t> out) {
  if (nx < 1 || ny < 1 || nz < 1 || nx > kEdtMaxAxis || ny > kEdtMaxAxis || nz > kEdtMaxAxis)
    throw std::invalid_argument("distance transform: grid dimensions out of range");
  const uint64_t cells = uint64_t(nx) * ny * nz;
  if (occupied.size() != cells || out.size() != cells)
    throw std::logic_error("distance transform: buffer sizes differ from the grid's");
  const auto t0 = SteadyClock::now();
  ensure_capacity(cells);
  const vk::Buffer& host_in = unified_ ? occupied_ : upload_;
  std::memcpy(host_in.mapped(), occupied.data(), cells);
  host_in.flush();

  VkCommandBuffer cmd = runner_.begin();
  if (!unified_) {
    const VkBufferCopy copy{0, 0, (cells + 3) / 4 * 4};
    vkCmdCopyBuffer(cmd, upload_.handle(), occupied_.handle(), 1, &copy);
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  }
  const uint32_t x = uint32_t(nx), y = uint32_t(ny), z = uint32_t(nz);
  // Rows along x: line l starts at l * nx. Along y: line x + nx * z starts at z * ny * nx + x.
  // Along z: line x + nx * y starts at itself.
  dispatch_lines(rows_, cmd, LinePush{x, y * z, 1, 1, x});
  vk::compute_to_compute(cmd);
  dispatch_lines(envelope_, cmd, LinePush{y, x * z, x, x, x * y});
  vk::compute_to_compute(cmd);
  dispatch_lines(envelope_, cmd, LinePush{z, x * y, x * y, x * y, 0});
  if (!unified_) {
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    const VkBufferCopy copy{0, 0, cells * 4};
    vkCmdCopyBuffer(cmd, squared_.handle(), readback_.handle(), 1, &copy);
  }
  vk::memory_barrier(cmd, unified_ ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : VK_PIPELINE_STAGE_TRANSFER_BIT,
                     unified_ ? VK_ACCESS_SHADER_WRITE_BIT : VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                     VK_ACCESS_HOST_READ_BIT);
  runner_.submit_and_wait();
  const vk::Buffer& host_out = unified_ ? squared_ : readback_;
  host_out.invalidate();
  std::memcpy(out.data(), host_out.mapped(), cells * 4);
  last_device_ms_ = ms_since(t0);
}

}  // namespace ort::gpu
