// A VkBuffer with its own VkDeviceMemory, mapped for its whole life when host-visible.
//
// One allocation per buffer is fine here: the back ends make a handful of long-lived
// buffers at start-up and grow a few of them geometrically, never per scan.
#pragma once

#include <cstdint>

#include <vulkan/vulkan.h>

#include "gpu/vk/vk_context.h"

namespace ort::vk {

class Buffer {
 public:
  Buffer() = default;
  // `required` memory flags must be met; `preferred` are taken where a type has them.
  // With VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT in `usage` the memory is allocated with
  // VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT (the device needs bufferDeviceAddress enabled).
  Buffer(const Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags required,
         VkMemoryPropertyFlags preferred = 0);
  ~Buffer() { release(); }
  Buffer(Buffer&& o) noexcept { *this = static_cast<Buffer&&>(o); }
  Buffer& operator=(Buffer&& o) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  explicit operator bool() const { return buffer_ != VK_NULL_HANDLE; }
  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  VkMemoryPropertyFlags memory_flags() const { return flags_; }
  bool host_visible() const { return mapped_ != nullptr; }
  // Host pointer to the whole buffer; nullptr unless host-visible.
  void* mapped() const { return mapped_; }
  template <class T>
  T* as() const {
    return static_cast<T*>(mapped_);
  }
  // For non-coherent host-visible memory: make host writes visible to the device, and
  // device writes visible to the host. No-ops on coherent memory.
  void flush(VkDeviceSize offset = 0, VkDeviceSize size = VK_WHOLE_SIZE) const;
  void invalidate(VkDeviceSize offset = 0, VkDeviceSize size = VK_WHOLE_SIZE) const;
  VkDeviceAddress device_address() const;

 private:
  void release();
  VkDevice device_ = VK_NULL_HANDLE;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  VkMemoryPropertyFlags flags_ = 0;
  void* mapped_ = nullptr;
};

}  // namespace ort::vk
