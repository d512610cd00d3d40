// Shader modules and compute pipelines whose bindings are all storage buffers.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <span>

#include <vulkan/vulkan.h>

#include "gpu/vk/vk_context.h"
#include "gpu/vk/vk_pipeline_objects.h"

namespace ort::vk {

class ShaderModule {
 public:
  ShaderModule() = default;
  ShaderModule(VkDevice device, std::span<const uint32_t> spirv);
  ~ShaderModule();
  ShaderModule(ShaderModule&& o) noexcept;
  ShaderModule& operator=(ShaderModule&& o) noexcept;
  ShaderModule(const ShaderModule&) = delete;
  ShaderModule& operator=(const ShaderModule&) = delete;
  VkShaderModule handle() const { return module_; }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VkShaderModule module_ = VK_NULL_HANDLE;
};

// One compute pipeline with `storage_buffers` bindings (set 0, bindings 0..n-1, all
// VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), a push-constant block of `push_bytes`, and its own
// descriptor set. Bind the buffers once (and again after one of them is re-created).
class ComputePipeline {
 public:
  ComputePipeline(const Context& ctx, std::span<const uint32_t> spirv, uint32_t storage_buffers, uint32_t push_bytes,
                  const VkSpecializationInfo* specialization = nullptr);
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;

  // Binding i gets buffers[i], whole range. Must not be called while a submitted command
  // buffer still uses the set.
  void bind_buffers(std::initializer_list<VkBuffer> buffers);
  // Binds pipeline + set, pushes constants (push_bytes of them), dispatches.
  void dispatch(VkCommandBuffer cmd, const void* push, uint32_t x, uint32_t y = 1, uint32_t z = 1) const;
  void dispatch_indirect(VkCommandBuffer cmd, const void* push, VkBuffer args, VkDeviceSize offset) const;

  VkPipeline handle() const { return objects_.pipeline; }
  VkPipelineLayout layout() const { return objects_.layout; }

 private:
  uint32_t bindings_;
  PipelineObjects objects_;
};

}  // namespace ort::vk
