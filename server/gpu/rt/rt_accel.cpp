#include "gpu/rt/rt_accel.h"

#include <chrono>
#include <cstring>
#include <optional>
#include <utility>
#include <vector>

#include "core/clock.h"
#include "gpu/rt/rt_functions.h"
#include "gpu/vk/vk_check.h"
#include "gpu/vk/vk_timestamps.h"

namespace ort::rt {
namespace {

VkDeviceSize align_up(VkDeviceSize v, VkDeviceSize a) { return a ? (v + a - 1) / a * a : v; }

VkDeviceSize scratch_alignment(const vk::Context& ctx) {
  return acceleration_structure_properties(ctx.physical_device()).minAccelerationStructureScratchOffsetAlignment;
}

// A scratch buffer for one build, with its device address aligned as the device requires.
struct Scratch {
  vk::Buffer buffer;
  VkDeviceAddress address = 0;
  Scratch(const vk::Context& ctx, VkDeviceSize size, VkDeviceSize alignment)
      : buffer(ctx, size + alignment, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
               VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) {
    address = align_up(buffer.device_address(), alignment);
  }
};

void build_barrier(VkCommandBuffer cmd) {
  vk::memory_barrier(
      cmd, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
      VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR | VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR,
      VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR);
}

}  // namespace

AccelerationStructure::AccelerationStructure(const vk::Context& ctx, const RtFunctions& fn,
                                             VkAccelerationStructureTypeKHR type, VkDeviceSize size)
    : fn_(&fn), device_(ctx.device()), size_(size) {
  buffer_ = vk::Buffer(
      ctx, size, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
      VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  VkAccelerationStructureCreateInfoKHR ci{};
  ci.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR;
  ci.buffer = buffer_.handle();
  ci.size = size;
  ci.type = type;
  vk::check(fn.create_acceleration_structure(device_, &ci, nullptr, &handle_), "vkCreateAccelerationStructureKHR");
}

AccelerationStructure& AccelerationStructure::operator=(AccelerationStructure&& o) noexcept {
  if (this != &o) {
    release();
    fn_ = o.fn_;
    device_ = o.device_;
    buffer_ = std::move(o.buffer_);
    handle_ = std::exchange(o.handle_, VK_NULL_HANDLE);
    size_ = std::exchange(o.size_, 0);
  }
  return *this;
}

void AccelerationStructure::release() {
  if (handle_) fn_->destroy_acceleration_structure(device_, handle_, nullptr);
  handle_ = VK_NULL_HANDLE;
  buffer_ = vk::Buffer();
}

VkDeviceAddress AccelerationStructure::address() const {
  VkAccelerationStructureDeviceAddressInfoKHR info{};
  info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR;
  info.accelerationStructure = handle_;
  return fn_->get_acceleration_structure_address(device_, &info);
}

namespace {

// One level of the BVH on its way: its geometry, build info and scratch buffer.
struct LevelBuild {
  VkAccelerationStructureGeometryKHR geometry{};
  VkAccelerationStructureBuildGeometryInfoKHR info{};
  uint32_t primitives = 0;
  VkDeviceSize scratch_bytes = 0;
  std::optional<Scratch> scratch;

  void record(VkCommandBuffer cmd, const RtFunctions& fn) {
    info.pGeometries = &geometry;  // set here: the struct may have moved since it was made
    const VkAccelerationStructureBuildRangeInfoKHR range{primitives, 0, 0, 0};
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
    fn.cmd_build_acceleration_structures(cmd, 1, &info, &ranges);
  }
};

// Sizes the level's build, creates the structure it builds into (`out`) and its scratch.
LevelBuild prepare_level(const vk::Context& ctx, const RtFunctions& fn, VkAccelerationStructureTypeKHR type,
                         VkGeometryTypeKHR geometry_type, const VkAccelerationStructureGeometryDataKHR& data,
                         uint32_t primitives, VkDeviceSize scratch_align, AccelerationStructure& out) {
  LevelBuild b;
  b.geometry.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
  b.geometry.geometryType = geometry_type;
  b.geometry.geometry = data;
  // Opaque: no any-hit shader; the intersection shader still runs for every candidate box.
  if (geometry_type == VK_GEOMETRY_TYPE_AABBS_KHR) b.geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  b.primitives = primitives;
  b.info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
  b.info.type = type;
  b.info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  b.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  b.info.geometryCount = 1;
  b.info.pGeometries = &b.geometry;
  VkAccelerationStructureBuildSizesInfoKHR sizes{};
  sizes.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR;
  fn.get_build_sizes(ctx.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &b.info, &primitives, &sizes);
  out = AccelerationStructure(ctx, fn, type, sizes.accelerationStructureSize);
  b.scratch.emplace(ctx, sizes.buildScratchSize, scratch_align);
  b.scratch_bytes = sizes.buildScratchSize;
  b.info.dstAccelerationStructure = out.handle();
  b.info.scratchData.deviceAddress = b.scratch->address;
  return b;
}

// The BLAS's data: the k^3 voxel boxes of one block.
VkAccelerationStructureGeometryDataKHR box_data(VkDeviceAddress boxes) {
  VkAccelerationStructureGeometryDataKHR d{};
  d.aabbs = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR, nullptr, {boxes}, sizeof(Aabb)};
  return d;
}

// The TLAS's data: a plain array of instance records.
VkAccelerationStructureGeometryDataKHR instance_data(VkDeviceAddress instances) {
  VkAccelerationStructureGeometryDataKHR d{};
  d.instances = {VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR, nullptr, VK_FALSE, {instances}};
  return d;
}

// The TLAS records: one instance of the BLAS per block, translated to the block's corner
// (voxel units). Instance i is block (i % bx, i / bx % by, i / (bx * by)); the intersection
// shader inverts that from gl_InstanceID (block_grid.h instance_block).
void write_instances(const BlockGrid& grid, VkDeviceAddress blas, VkAccelerationStructureInstanceKHR* records) {
  for (uint64_t i = 0; i < grid.instance_count(); ++i) {
    VkAccelerationStructureInstanceKHR r{};
    float t[3];
    instance_translation(grid, i, t);
    r.transform.matrix[0][0] = r.transform.matrix[1][1] = r.transform.matrix[2][2] = 1.0f;
    r.transform.matrix[0][3] = t[0];
    r.transform.matrix[1][3] = t[1];
    r.transform.matrix[2][3] = t[2];
    r.instanceCustomIndex = 0;
    r.mask = 0xFF;
    r.instanceShaderBindingTableRecordOffset = 0;
    r.flags = VK_GEOMETRY_INSTANCE_FORCE_OPAQUE_BIT_KHR;
    r.accelerationStructureReference = blas;
    records[i] = r;
  }
}

// Runs both builds in one submission; returns their device time.
double run_builds(const vk::Context& ctx, const RtFunctions& fn, vk::CommandRunner& runner, LevelBuild& blas,
                  LevelBuild& tlas) {
  vk::TimestampQueries stamps(ctx, 2);
  VkCommandBuffer cmd = runner.begin();
  stamps.reset(cmd);
  stamps.write(cmd, 0, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
  blas.record(cmd, fn);
  build_barrier(cmd);  // the TLAS build reads the BLAS
  tlas.record(cmd, fn);
  build_barrier(cmd);
  stamps.write(cmd, 1, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  runner.submit_and_wait();
  stamps.fetch(2);
  return stamps.elapsed_ms(0, 1);
}

}  // namespace

SharedBvh build_shared_bvh(const vk::Context& ctx, const RtFunctions& fn, const BlockGrid& grid,
                           vk::CommandRunner& runner, float aabb_margin) {
  const auto t0 = SteadyClock::now();
  SharedBvh bvh;
  const VkDeviceSize scratch_align = scratch_alignment(ctx);
  const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  const VkBufferUsageFlags input_usage =
      VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

  // BLAS: the k^3 voxel boxes of one block (enlarged by aabb_margin).
  const std::vector<Aabb> boxes = block_aabbs(grid.block, aabb_margin);
  vk::Buffer box_buffer(ctx, boxes.size() * sizeof(Aabb), input_usage, host);
  std::memcpy(box_buffer.mapped(), boxes.data(), boxes.size() * sizeof(Aabb));
  LevelBuild blas =
      prepare_level(ctx, fn, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, VK_GEOMETRY_TYPE_AABBS_KHR,
                    box_data(box_buffer.device_address()), uint32_t(boxes.size()), scratch_align, bvh.blas);

  // TLAS: one instance of the BLAS per block.
  bvh.instance_bytes = grid.instance_count() * sizeof(VkAccelerationStructureInstanceKHR);
  vk::Buffer instance_buffer(ctx, bvh.instance_bytes, input_usage, host, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  write_instances(grid, bvh.blas.address(), instance_buffer.as<VkAccelerationStructureInstanceKHR>());
  instance_buffer.flush();
  LevelBuild tlas = prepare_level(ctx, fn, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, VK_GEOMETRY_TYPE_INSTANCES_KHR,
                                  instance_data(instance_buffer.device_address()), uint32_t(grid.instance_count()),
                                  scratch_align, bvh.tlas);
  bvh.scratch_bytes = blas.scratch_bytes + tlas.scratch_bytes;

  bvh.gpu_build_ms = run_builds(ctx, fn, runner, blas, tlas);
  bvh.build_ms = ms_since(t0);
  return bvh;
}

}  // namespace ort::rt
