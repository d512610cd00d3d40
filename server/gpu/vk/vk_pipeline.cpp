#include "gpu/vk/vk_pipeline.h"

#include <stdexcept>
#include <utility>
#include <vector>

#include "gpu/vk/vk_check.h"

namespace ort::vk {

ShaderModule::ShaderModule(VkDevice device, std::span<const uint32_t> spirv) : device_(device) {
  VkShaderModuleCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  ci.codeSize = spirv.size_bytes();
  ci.pCode = spirv.data();
  check(vkCreateShaderModule(device_, &ci, nullptr, &module_), "vkCreateShaderModule");
}

ShaderModule::~ShaderModule() {
  if (module_) vkDestroyShaderModule(device_, module_, nullptr);
}

ShaderModule::ShaderModule(ShaderModule&& o) noexcept
    : device_(o.device_), module_(std::exchange(o.module_, VK_NULL_HANDLE)) {}

ShaderModule& ShaderModule::operator=(ShaderModule&& o) noexcept {
  if (this != &o) {
    if (module_) vkDestroyShaderModule(device_, module_, nullptr);
    device_ = o.device_;
    module_ = std::exchange(o.module_, VK_NULL_HANDLE);
  }
  return *this;
}

ComputePipeline::ComputePipeline(const Context& ctx, std::span<const uint32_t> spirv, uint32_t storage_buffers,
                                 uint32_t push_bytes, const VkSpecializationInfo* specialization)
    : device_(ctx.device()), bindings_(storage_buffers), push_bytes_(push_bytes) {
  if (push_bytes > ctx.properties().limits.maxPushConstantsSize) {
    throw std::runtime_error("push constants larger than the device allows");
  }
  try {
    std::vector<VkDescriptorSetLayoutBinding> b(storage_buffers);
    for (uint32_t i = 0; i < storage_buffers; ++i) {
      b[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    }
    VkDescriptorSetLayoutCreateInfo dl{};
    dl.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    dl.bindingCount = storage_buffers;
    dl.pBindings = b.data();
    check(vkCreateDescriptorSetLayout(device_, &dl, nullptr, &set_layout_), "vkCreateDescriptorSetLayout");

    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes};
    VkPipelineLayoutCreateInfo pl{};
    pl.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &set_layout_;
    pl.pushConstantRangeCount = push_bytes ? 1 : 0;
    pl.pPushConstantRanges = &range;
    check(vkCreatePipelineLayout(device_, &pl, nullptr, &layout_), "vkCreatePipelineLayout");

    ShaderModule module(device_, spirv);
    VkComputePipelineCreateInfo ci{};
    ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module.handle();
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = specialization;
    ci.layout = layout_;
    check(vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline_), "vkCreateComputePipelines");

    VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, storage_buffers};
    VkDescriptorPoolCreateInfo dp{};
    dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dp.maxSets = 1;
    dp.poolSizeCount = 1;
    dp.pPoolSizes = &ps;
    check(vkCreateDescriptorPool(device_, &dp, nullptr, &pool_), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo ai{};
    ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    ai.descriptorPool = pool_;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &set_layout_;
    check(vkAllocateDescriptorSets(device_, &ai, &set_), "vkAllocateDescriptorSets");
  } catch (...) {
    destroy();
    throw;
  }
}

ComputePipeline::~ComputePipeline() { destroy(); }

void ComputePipeline::destroy() {
  if (pool_) vkDestroyDescriptorPool(device_, pool_, nullptr);
  if (pipeline_) vkDestroyPipeline(device_, pipeline_, nullptr);
  if (layout_) vkDestroyPipelineLayout(device_, layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(device_, set_layout_, nullptr);
  pool_ = VK_NULL_HANDLE;
  pipeline_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  set_layout_ = VK_NULL_HANDLE;
}

void ComputePipeline::bind_buffers(std::initializer_list<VkBuffer> buffers) {
  if (buffers.size() != bindings_) throw std::logic_error("bind_buffers: wrong number of buffers");
  std::vector<VkDescriptorBufferInfo> info;
  std::vector<VkWriteDescriptorSet> writes;
  info.reserve(bindings_);
  for (VkBuffer b : buffers) info.push_back({b, 0, VK_WHOLE_SIZE});
  for (uint32_t i = 0; i < bindings_; ++i) {
    VkWriteDescriptorSet w{};
    w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w.dstSet = set_;
    w.dstBinding = i;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    w.pBufferInfo = &info[i];
    writes.push_back(w);
  }
  vkUpdateDescriptorSets(device_, uint32_t(writes.size()), writes.data(), 0, nullptr);
}

void ComputePipeline::bind(VkCommandBuffer cmd, const void* push) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 0, nullptr);
  if (push_bytes_) vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes_, push);
}

void ComputePipeline::dispatch(VkCommandBuffer cmd, const void* push, uint32_t x, uint32_t y, uint32_t z) const {
  bind(cmd, push);
  vkCmdDispatch(cmd, x, y, z);
}

void ComputePipeline::dispatch_indirect(VkCommandBuffer cmd, const void* push, VkBuffer args,
                                        VkDeviceSize offset) const {
  bind(cmd, push);
  vkCmdDispatchIndirect(cmd, args, offset);
}

}  // namespace ort::vk
