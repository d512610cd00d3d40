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

namespace {

std::vector<VkDescriptorSetLayoutBinding> storage_bindings(uint32_t count) {
  std::vector<VkDescriptorSetLayoutBinding> b(count);
  for (uint32_t i = 0; i < count; ++i)
    b[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  return b;
}

uint32_t checked_push_bytes(const Context& ctx, uint32_t push_bytes) {
  if (push_bytes > ctx.properties().limits.maxPushConstantsSize) {
    throw std::runtime_error("push constants larger than the device allows");
  }
  return push_bytes;
}

}  // namespace

ComputePipeline::ComputePipeline(const Context& ctx, std::span<const uint32_t> spirv, uint32_t storage_buffers,
                                 uint32_t push_bytes, const VkSpecializationInfo* specialization)
    : bindings_(storage_buffers),
      objects_(ctx.device(), storage_bindings(storage_buffers),
               {VK_SHADER_STAGE_COMPUTE_BIT, 0, checked_push_bytes(ctx, push_bytes)}) {
  ShaderModule module(objects_.device, spirv);
  VkComputePipelineCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = module.handle();
  ci.stage.pName = "main";
  ci.stage.pSpecializationInfo = specialization;
  ci.layout = objects_.layout;
  check(vkCreateComputePipelines(objects_.device, VK_NULL_HANDLE, 1, &ci, nullptr, &objects_.pipeline),
        "vkCreateComputePipelines");
}

void ComputePipeline::bind_buffers(std::initializer_list<VkBuffer> buffers) {
  if (buffers.size() != bindings_) throw std::logic_error("bind_buffers: wrong number of buffers");
  objects_.write_storage_buffers(std::span<const VkBuffer>(buffers.begin(), buffers.size()));
}

void ComputePipeline::dispatch(VkCommandBuffer cmd, const void* push, uint32_t x, uint32_t y, uint32_t z) const {
  objects_.bind(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, push);
  vkCmdDispatch(cmd, x, y, z);
}

void ComputePipeline::dispatch_indirect(VkCommandBuffer cmd, const void* push, VkBuffer args,
                                        VkDeviceSize offset) const {
  objects_.bind(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, push);
  vkCmdDispatchIndirect(cmd, args, offset);
}

}  // namespace ort::vk
