// What every pipeline here holds besides its shaders: one descriptor set (its layout, the
// pool it comes from, the set), the pipeline layout (that set plus one push-constant range)
// and the pipeline. The compute pipelines (vk_pipeline.h) and the ray-tracing pipeline
// (rt/rt_pipeline.h) differ only in how the VkPipeline itself is made.
#pragma once

#include <cstdint>
#include <span>

#include <vulkan/vulkan.h>

namespace ort::vk {

class PipelineObjects {
 public:
  // Makes the set layout from `bindings`, a pool holding exactly one set of them, the set,
  // and the pipeline layout with `push` (no push-constant range when push.size is 0).
  // `pipeline` is left for the owner to create with `layout`.
  PipelineObjects(VkDevice device, std::span<const VkDescriptorSetLayoutBinding> bindings, VkPushConstantRange push);
  ~PipelineObjects() { destroy(); }
  PipelineObjects(const PipelineObjects&) = delete;
  PipelineObjects& operator=(const PipelineObjects&) = delete;

  // Points bindings first_binding.. of the set at whole buffers. Not while a submitted
  // command buffer still uses the set.
  void write_storage_buffers(std::span<const VkBuffer> buffers, uint32_t first_binding = 0) const;
  // Binds the pipeline and the set at `point` and pushes the push-constant range from `push`.
  void bind(VkCommandBuffer cmd, VkPipelineBindPoint point, const void* push) const;

  VkDevice device = VK_NULL_HANDLE;
  VkPushConstantRange push_range{};
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;  // freed with the pool

 private:
  void make_set(std::span<const VkDescriptorSetLayoutBinding> bindings);
  void destroy();
};

}  // namespace ort::vk
