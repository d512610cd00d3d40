#include "gpu/rt/rt_pipeline.h"

#include <array>
#include <cstring>
#include <vector>

#include "gpu/vk/vk_check.h"
#include "gpu/vk/vk_pipeline.h"
#include "shaders/rt_miss_rmiss_spv.h"
#include "shaders/rt_shoot_rgen_spv.h"
#include "shaders/rt_voxel_rint_spv.h"

namespace ort::rt {
namespace {

constexpr VkShaderStageFlags kShaderStages = VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_INTERSECTION_BIT_KHR;
constexpr uint32_t kGroupCount = 3;  // raygen, miss, procedural hit group

uint32_t align_up(uint32_t v, uint32_t a) { return a ? (v + a - 1) / a * a : v; }

// Bindings 0..3: the GPU ray space's storage buffers; 4: the TLAS.
constexpr std::array<VkDescriptorSetLayoutBinding, 5> kBindings = {{
    {0, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kShaderStages, nullptr},
    {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kShaderStages, nullptr},
    {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kShaderStages, nullptr},
    {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kShaderStages, nullptr},
    {4, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR, nullptr},
}};

std::array<VkRayTracingShaderGroupCreateInfoKHR, kGroupCount> shader_groups() {
  std::array<VkRayTracingShaderGroupCreateInfoKHR, kGroupCount> groups{};
  for (auto& g : groups) {
    g.sType = VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR;
    g.generalShader = g.closestHitShader = g.anyHitShader = g.intersectionShader = VK_SHADER_UNUSED_KHR;
  }
  groups[0].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
  groups[0].generalShader = 0;
  groups[1].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
  groups[1].generalShader = 1;
  groups[2].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_PROCEDURAL_HIT_GROUP_KHR;
  groups[2].intersectionShader = 2;
  return groups;
}

}  // namespace

RayTracingPipeline::RayTracingPipeline(const vk::Context& ctx, const RtFunctions& fn, const BlockGrid& grid,
                                       uint32_t push_bytes, bool mark_candidates)
    : fn_(&fn), objects_(ctx.device(), kBindings, {kShaderStages, 0, push_bytes}) {
  create_pipeline(fn, grid, mark_candidates);
  create_binding_table(ctx, fn, kGroupCount);
}

void RayTracingPipeline::create_pipeline(const RtFunctions& fn, const BlockGrid& grid, bool mark_candidates) {
  const VkDevice device = objects_.device;
  vk::ShaderModule rgen(device, rt_shoot_rgen_spv), rmiss(device, rt_miss_rmiss_spv), rint(device, rt_voxel_rint_spv);
  const uint32_t spec_values[4] = {uint32_t(grid.block), uint32_t(grid.blocks[0]), uint32_t(grid.blocks[1]),
                                   mark_candidates ? 1u : 0u};
  const VkSpecializationMapEntry spec_entries[4] = {{0, 0, 4}, {1, 4, 4}, {2, 8, 4}, {3, 12, 4}};
  const VkSpecializationInfo spec{4, spec_entries, sizeof(spec_values), spec_values};
  std::array<VkPipelineShaderStageCreateInfo, 3> stages{};
  const VkShaderStageFlagBits stage_bits[3] = {VK_SHADER_STAGE_RAYGEN_BIT_KHR, VK_SHADER_STAGE_MISS_BIT_KHR,
                                               VK_SHADER_STAGE_INTERSECTION_BIT_KHR};
  const VkShaderModule modules[3] = {rgen.handle(), rmiss.handle(), rint.handle()};
  for (int i = 0; i < 3; ++i) {
    stages[i].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[i].stage = stage_bits[i];
    stages[i].module = modules[i];
    stages[i].pName = "main";
  }
  stages[2].pSpecializationInfo = &spec;

  const auto groups = shader_groups();
  VkRayTracingPipelineCreateInfoKHR ci{};
  ci.sType = VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR;
  ci.stageCount = uint32_t(stages.size());
  ci.pStages = stages.data();
  ci.groupCount = uint32_t(groups.size());
  ci.pGroups = groups.data();
  ci.maxPipelineRayRecursionDepth = 1;
  ci.layout = objects_.layout;
  vk::check(
      fn.create_ray_tracing_pipelines(device, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &ci, nullptr, &objects_.pipeline),
      "vkCreateRayTracingPipelinesKHR");
}

// Shader binding table: one record per group, each region on its own base alignment.
void RayTracingPipeline::create_binding_table(const vk::Context& ctx, const RtFunctions& fn, uint32_t group_count) {
  const auto rp = vk::extension_properties<VkPhysicalDeviceRayTracingPipelinePropertiesKHR>(
      ctx.physical_device(), VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR);
  const uint32_t handle = rp.shaderGroupHandleSize;
  const uint32_t stride = align_up(handle, rp.shaderGroupHandleAlignment);
  const uint32_t region = align_up(stride, rp.shaderGroupBaseAlignment);
  std::vector<uint8_t> handles(size_t(handle) * group_count);
  vk::check(
      fn.get_shader_group_handles(objects_.device, objects_.pipeline, 0, group_count, handles.size(), handles.data()),
      "vkGetRayTracingShaderGroupHandlesKHR");
  sbt_ = vk::Buffer(ctx, VkDeviceSize(region) * group_count + rp.shaderGroupBaseAlignment,
                    VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                    VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                    VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  const VkDeviceAddress base = sbt_.device_address();
  const VkDeviceAddress aligned =
      (base + rp.shaderGroupBaseAlignment - 1) / rp.shaderGroupBaseAlignment * rp.shaderGroupBaseAlignment;
  auto* bytes = static_cast<uint8_t*>(sbt_.mapped()) + (aligned - base);
  std::memset(sbt_.mapped(), 0, sbt_.size());
  for (size_t g = 0; g < group_count; ++g) std::memcpy(bytes + g * region, handles.data() + g * handle, handle);
  sbt_.flush();
  raygen_ = {aligned, stride, stride};  // the raygen region's size must equal its stride
  miss_ = {aligned + region, stride, stride};
  hit_ = {aligned + 2 * VkDeviceAddress(region), stride, stride};
}

void RayTracingPipeline::bind(VkBuffer rays, VkBuffer grid, VkBuffer touched, VkBuffer counters,
                              VkAccelerationStructureKHR tlas) {
  const VkBuffer buffers[4] = {rays, grid, touched, counters};
  objects_.write_storage_buffers(buffers);
  VkWriteDescriptorSetAccelerationStructureKHR as{};
  as.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR;
  as.accelerationStructureCount = 1;
  as.pAccelerationStructures = &tlas;
  VkWriteDescriptorSet w{};
  w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
  w.pNext = &as;
  w.dstSet = objects_.set;
  w.dstBinding = 4;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
  vkUpdateDescriptorSets(objects_.device, 1, &w, 0, nullptr);
}

void RayTracingPipeline::trace(VkCommandBuffer cmd, const void* push, uint32_t width, uint32_t height) const {
  objects_.bind(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, push);
  fn_->cmd_trace_rays(cmd, &raygen_, &miss_, &hit_, &callable_, width, height, 1);
}

}  // namespace ort::rt
