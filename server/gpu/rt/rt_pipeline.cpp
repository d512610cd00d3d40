#include "gpu/rt/rt_pipeline.h"

#include <array>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "gpu/vk/vk_check.h"
#include "gpu/vk/vk_pipeline.h"
#include "shaders/rt_miss_rmiss_spv.h"
#include "shaders/rt_shoot_rgen_spv.h"
#include "shaders/rt_voxel_rint_spv.h"

namespace ort::rt {
namespace {

constexpr VkShaderStageFlags kShaderStages = VK_SHADER_STAGE_RAYGEN_BIT_KHR | VK_SHADER_STAGE_INTERSECTION_BIT_KHR;
uint32_t align_up(uint32_t v, uint32_t a) { return a ? (v + a - 1) / a * a : v; }

}  // namespace

RayTracingPipeline::RayTracingPipeline(const vk::Context& ctx, const RtFunctions& fn, const SpaceLayout& layout,
                                       uint32_t push_bytes, bool mark_candidates)
    : fn_(&fn), device_(ctx.device()), push_bytes_(push_bytes) {
  try {
    std::array<VkDescriptorSetLayoutBinding, 5> b{};
    for (uint32_t i = 0; i < 4; ++i) b[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, kShaderStages, nullptr};
    b[4] = {4, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, VK_SHADER_STAGE_RAYGEN_BIT_KHR, nullptr};
    VkDescriptorSetLayoutCreateInfo dl{};
    dl.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    dl.bindingCount = uint32_t(b.size());
    dl.pBindings = b.data();
    vk::check(vkCreateDescriptorSetLayout(device_, &dl, nullptr, &set_layout_), "vkCreateDescriptorSetLayout");

    const VkPushConstantRange range{kShaderStages, 0, push_bytes};
    VkPipelineLayoutCreateInfo pl{};
    pl.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &set_layout_;
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &range;
    vk::check(vkCreatePipelineLayout(device_, &pl, nullptr, &layout_), "vkCreatePipelineLayout");

    vk::ShaderModule rgen(device_, rt_shoot_rgen_spv), rmiss(device_, rt_miss_rmiss_spv),
        rint(device_, rt_voxel_rint_spv);
    const uint32_t spec_values[4] = {uint32_t(layout.block), uint32_t(layout.blocks[0]), uint32_t(layout.blocks[1]),
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

    std::array<VkRayTracingShaderGroupCreateInfoKHR, 3> groups{};
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

    VkRayTracingPipelineCreateInfoKHR ci{};
    ci.sType = VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR;
    ci.stageCount = uint32_t(stages.size());
    ci.pStages = stages.data();
    ci.groupCount = uint32_t(groups.size());
    ci.pGroups = groups.data();
    ci.maxPipelineRayRecursionDepth = 1;
    ci.layout = layout_;
    vk::check(fn.create_ray_tracing_pipelines(device_, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline_),
              "vkCreateRayTracingPipelinesKHR");

    // Shader binding table: one record per group, each region on its own base alignment.
    VkPhysicalDeviceRayTracingPipelinePropertiesKHR rp{};
    rp.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR;
    VkPhysicalDeviceProperties2 p2{};
    p2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    p2.pNext = &rp;
    vkGetPhysicalDeviceProperties2(ctx.physical_device(), &p2);
    const uint32_t handle = rp.shaderGroupHandleSize;
    const uint32_t stride = align_up(handle, rp.shaderGroupHandleAlignment);
    const uint32_t region = align_up(stride, rp.shaderGroupBaseAlignment);
    std::vector<uint8_t> handles(size_t(handle) * groups.size());
    vk::check(fn.get_shader_group_handles(device_, pipeline_, 0, uint32_t(groups.size()), handles.size(), handles.data()),
              "vkGetRayTracingShaderGroupHandlesKHR");
    sbt_ = vk::Buffer(ctx, VkDeviceSize(region) * groups.size() + rp.shaderGroupBaseAlignment,
                      VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT,
                      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                      VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    const VkDeviceAddress base = sbt_.device_address();
    const VkDeviceAddress aligned = (base + rp.shaderGroupBaseAlignment - 1) / rp.shaderGroupBaseAlignment *
                                    rp.shaderGroupBaseAlignment;
    auto* bytes = static_cast<uint8_t*>(sbt_.mapped()) + (aligned - base);
    std::memset(sbt_.mapped(), 0, sbt_.size());
    for (size_t g = 0; g < groups.size(); ++g) std::memcpy(bytes + g * region, handles.data() + g * handle, handle);
    sbt_.flush();
    raygen_ = {aligned, stride, stride};  // the raygen region's size must equal its stride
    miss_ = {aligned + region, stride, stride};
    hit_ = {aligned + 2 * VkDeviceAddress(region), stride, stride};

    VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 4},
                                     {VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1}};
    VkDescriptorPoolCreateInfo dp{};
    dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dp.maxSets = 1;
    dp.poolSizeCount = 2;
    dp.pPoolSizes = sizes;
    vk::check(vkCreateDescriptorPool(device_, &dp, nullptr, &pool_), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo ai{};
    ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    ai.descriptorPool = pool_;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &set_layout_;
    vk::check(vkAllocateDescriptorSets(device_, &ai, &set_), "vkAllocateDescriptorSets");
  } catch (...) {
    destroy();
    throw;
  }
}

RayTracingPipeline::~RayTracingPipeline() { destroy(); }

void RayTracingPipeline::destroy() {
  if (pool_) vkDestroyDescriptorPool(device_, pool_, nullptr);
  if (pipeline_) vkDestroyPipeline(device_, pipeline_, nullptr);
  if (layout_) vkDestroyPipelineLayout(device_, layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(device_, set_layout_, nullptr);
  pool_ = VK_NULL_HANDLE;
  pipeline_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  set_layout_ = VK_NULL_HANDLE;
}

void RayTracingPipeline::bind(VkBuffer rays, VkBuffer grid, VkBuffer touched, VkBuffer counters,
                              VkAccelerationStructureKHR tlas) {
  const VkDescriptorBufferInfo info[4] = {
      {rays, 0, VK_WHOLE_SIZE}, {grid, 0, VK_WHOLE_SIZE}, {touched, 0, VK_WHOLE_SIZE}, {counters, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSetAccelerationStructureKHR as{};
  as.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR;
  as.accelerationStructureCount = 1;
  as.pAccelerationStructures = &tlas;
  std::array<VkWriteDescriptorSet, 5> w{};
  for (uint32_t i = 0; i < 5; ++i) {
    w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w[i].dstSet = set_;
    w[i].dstBinding = i;
    w[i].descriptorCount = 1;
    if (i < 4) {
      w[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      w[i].pBufferInfo = &info[i];
    } else {
      w[i].descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
      w[i].pNext = &as;
    }
  }
  vkUpdateDescriptorSets(device_, uint32_t(w.size()), w.data(), 0, nullptr);
}

void RayTracingPipeline::trace(VkCommandBuffer cmd, const void* push, uint32_t width, uint32_t height) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipeline_);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, layout_, 0, 1, &set_, 0, nullptr);
  vkCmdPushConstants(cmd, layout_, kShaderStages, 0, push_bytes_, push);
  fn_->cmd_trace_rays(cmd, &raygen_, &miss_, &hit_, &callable_, width, height, 1);
}

}  // namespace ort::rt
