#include "gpu/vk/vk_pipeline_objects.h"

#include <map>
#include <utility>
#include <vector>

#include "gpu/vk/vk_check.h"

namespace ort::vk {

PipelineObjects::PipelineObjects(VkDevice dev, std::span<const VkDescriptorSetLayoutBinding> bindings,
                                 VkPushConstantRange push)
    : device(dev), push_range(push) {
  try {
    make_set(bindings);
    VkPipelineLayoutCreateInfo pl{};
    pl.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &set_layout;
    pl.pushConstantRangeCount = push.size ? 1 : 0;
    pl.pPushConstantRanges = &push_range;
    check(vkCreatePipelineLayout(device, &pl, nullptr, &layout), "vkCreatePipelineLayout");
  } catch (...) {
    destroy();  // the destructor does not run for an object whose constructor threw
    throw;
  }
}

void PipelineObjects::make_set(std::span<const VkDescriptorSetLayoutBinding> bindings) {
  VkDescriptorSetLayoutCreateInfo dl{};
  dl.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  dl.bindingCount = uint32_t(bindings.size());
  dl.pBindings = bindings.data();
  check(vkCreateDescriptorSetLayout(device, &dl, nullptr, &set_layout), "vkCreateDescriptorSetLayout");

  std::map<VkDescriptorType, uint32_t> per_type;
  for (const VkDescriptorSetLayoutBinding& b : bindings) per_type[b.descriptorType] += b.descriptorCount;
  std::vector<VkDescriptorPoolSize> sizes;
  for (const auto& [type, count] : per_type) sizes.push_back({type, count});
  VkDescriptorPoolCreateInfo dp{};
  dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dp.maxSets = 1;
  dp.poolSizeCount = uint32_t(sizes.size());
  dp.pPoolSizes = sizes.data();
  check(vkCreateDescriptorPool(device, &dp, nullptr, &pool), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  ai.descriptorPool = pool;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &set_layout;
  check(vkAllocateDescriptorSets(device, &ai, &set), "vkAllocateDescriptorSets");
}

void PipelineObjects::destroy() {
  set = VK_NULL_HANDLE;  // freed with its pool
  if (pool) vkDestroyDescriptorPool(device, std::exchange(pool, VK_NULL_HANDLE), nullptr);
  if (pipeline) vkDestroyPipeline(device, std::exchange(pipeline, VK_NULL_HANDLE), nullptr);
  if (layout) vkDestroyPipelineLayout(device, std::exchange(layout, VK_NULL_HANDLE), nullptr);
  if (set_layout) vkDestroyDescriptorSetLayout(device, std::exchange(set_layout, VK_NULL_HANDLE), nullptr);
}

void PipelineObjects::write_storage_buffers(std::span<const VkBuffer> buffers, uint32_t first_binding) const {
  std::vector<VkDescriptorBufferInfo> info;
  info.reserve(buffers.size());
  for (VkBuffer b : buffers) info.push_back({b, 0, VK_WHOLE_SIZE});
  std::vector<VkWriteDescriptorSet> writes(buffers.size());
  for (size_t i = 0; i < buffers.size(); ++i) {
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = set;
    writes[i].dstBinding = first_binding + uint32_t(i);
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &info[i];
  }
  vkUpdateDescriptorSets(device, uint32_t(writes.size()), writes.data(), 0, nullptr);
}

void PipelineObjects::bind(VkCommandBuffer cmd, VkPipelineBindPoint point, const void* push) const {
  vkCmdBindPipeline(cmd, point, pipeline);
  vkCmdBindDescriptorSets(cmd, point, layout, 0, 1, &set, 0, nullptr);
  if (push_range.size) vkCmdPushConstants(cmd, layout, push_range.stageFlags, 0, push_range.size, push);
}

}  // namespace ort::vk
