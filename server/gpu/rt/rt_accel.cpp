#include "gpu/rt/rt_accel.h"

#include <chrono>
#include <cstring>
#include <utility>

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
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                     VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR,
                     VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR | VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR,
                     VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR);
}

}  // namespace

AccelerationStructure::AccelerationStructure(const vk::Context& ctx, const RtFunctions& fn,
                                             VkAccelerationStructureTypeKHR type, VkDeviceSize size)
    : fn_(&fn), device_(ctx.device()), size_(size) {
  buffer_ = vk::Buffer(ctx, size,
                       VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
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

SharedBvh build_shared_bvh(const vk::Context& ctx, const RtFunctions& fn, const SpaceLayout& layout,
                           vk::CommandRunner& runner, float aabb_margin) {
  const auto t0 = std::chrono::steady_clock::now();
  SharedBvh bvh;
  const VkDevice dev = ctx.device();
  const VkDeviceSize scratch_align = scratch_alignment(ctx);
  const VkMemoryPropertyFlags host = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  const VkBufferUsageFlags input_usage =
      VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

  // --- BLAS: the k^3 voxel boxes of one block (enlarged by kAabbMargin).
  const std::vector<Aabb> boxes = block_aabbs(layout.block, aabb_margin);
  vk::Buffer aabb_buffer(ctx, boxes.size() * sizeof(Aabb), input_usage, host);
  std::memcpy(aabb_buffer.mapped(), boxes.data(), boxes.size() * sizeof(Aabb));

  VkAccelerationStructureGeometryKHR blas_geometry{};
  blas_geometry.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
  blas_geometry.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
  blas_geometry.geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
  blas_geometry.geometry.aabbs.data.deviceAddress = aabb_buffer.device_address();
  blas_geometry.geometry.aabbs.stride = sizeof(Aabb);
  // Opaque: no any-hit shader; the intersection shader still runs for every candidate box.
  blas_geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  VkAccelerationStructureBuildGeometryInfoKHR blas_info{};
  blas_info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
  blas_info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  blas_info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  blas_info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  blas_info.geometryCount = 1;
  blas_info.pGeometries = &blas_geometry;
  const uint32_t box_count = uint32_t(boxes.size());
  VkAccelerationStructureBuildSizesInfoKHR blas_sizes{};
  blas_sizes.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR;
  fn.get_build_sizes(dev, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &blas_info, &box_count, &blas_sizes);
  bvh.blas = AccelerationStructure(ctx, fn, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                   blas_sizes.accelerationStructureSize);
  Scratch blas_scratch(ctx, blas_sizes.buildScratchSize, scratch_align);
  blas_info.dstAccelerationStructure = bvh.blas.handle();
  blas_info.scratchData.deviceAddress = blas_scratch.address;

  // --- TLAS: one instance of the BLAS per block, translated to the block's corner (voxel
  // units). Instance i is block (i % bx, i / bx % by, i / (bx * by)); the intersection
  // shader inverts that from gl_InstanceID (rt_space.h instance_block).
  const uint64_t instances = layout.instance_count();
  bvh.instance_bytes = instances * sizeof(VkAccelerationStructureInstanceKHR);
  vk::Buffer instance_buffer(ctx, bvh.instance_bytes, input_usage, host, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  const VkDeviceAddress blas_address = bvh.blas.address();
  auto* records = instance_buffer.as<VkAccelerationStructureInstanceKHR>();
  for (uint64_t i = 0; i < instances; ++i) {
    VkAccelerationStructureInstanceKHR r{};
    float t[3];
    instance_translation(layout, i, t);
    r.transform.matrix[0][0] = r.transform.matrix[1][1] = r.transform.matrix[2][2] = 1.0f;
    r.transform.matrix[0][3] = t[0];
    r.transform.matrix[1][3] = t[1];
    r.transform.matrix[2][3] = t[2];
    r.instanceCustomIndex = 0;
    r.mask = 0xFF;
    r.instanceShaderBindingTableRecordOffset = 0;
    r.flags = VK_GEOMETRY_INSTANCE_FORCE_OPAQUE_BIT_KHR;
    r.accelerationStructureReference = blas_address;
    records[i] = r;
  }
  instance_buffer.flush();

  VkAccelerationStructureGeometryKHR tlas_geometry{};
  tlas_geometry.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
  tlas_geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  tlas_geometry.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  tlas_geometry.geometry.instances.arrayOfPointers = VK_FALSE;
  tlas_geometry.geometry.instances.data.deviceAddress = instance_buffer.device_address();
  VkAccelerationStructureBuildGeometryInfoKHR tlas_info{};
  tlas_info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
  tlas_info.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  tlas_info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  tlas_info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  tlas_info.geometryCount = 1;
  tlas_info.pGeometries = &tlas_geometry;
  const uint32_t instance_count = uint32_t(instances);
  VkAccelerationStructureBuildSizesInfoKHR tlas_sizes{};
  tlas_sizes.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR;
  fn.get_build_sizes(dev, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &tlas_info, &instance_count, &tlas_sizes);
  bvh.tlas = AccelerationStructure(ctx, fn, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR,
                                   tlas_sizes.accelerationStructureSize);
  Scratch tlas_scratch(ctx, tlas_sizes.buildScratchSize, scratch_align);
  tlas_info.dstAccelerationStructure = bvh.tlas.handle();
  tlas_info.scratchData.deviceAddress = tlas_scratch.address;
  bvh.scratch_bytes = blas_sizes.buildScratchSize + tlas_sizes.buildScratchSize;

  vk::TimestampQueries stamps(ctx, 2);
  VkCommandBuffer cmd = runner.begin();
  stamps.reset(cmd);
  stamps.write(cmd, 0, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
  const VkAccelerationStructureBuildRangeInfoKHR blas_range{box_count, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* blas_ranges = &blas_range;
  fn.cmd_build_acceleration_structures(cmd, 1, &blas_info, &blas_ranges);
  build_barrier(cmd);  // the TLAS build reads the BLAS
  const VkAccelerationStructureBuildRangeInfoKHR tlas_range{instance_count, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* tlas_ranges = &tlas_range;
  fn.cmd_build_acceleration_structures(cmd, 1, &tlas_info, &tlas_ranges);
  build_barrier(cmd);
  stamps.write(cmd, 1, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  runner.submit_and_wait();
  stamps.fetch(2);
  bvh.gpu_build_ms = stamps.elapsed_ms(0, 1);
  bvh.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return bvh;
}

}  // namespace ort::rt
