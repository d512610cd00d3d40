// The Vulkan instance and one logical device with a compute queue: what every GPU back end
// (vulkan compute, rt) starts from.
//
// Device choice: the devices that meet the requirements (Vulkan 1.2, the extra extensions,
// shaderFloat64/shaderInt64 when asked for, a compute queue), best type first: discrete GPU,
// then integrated, virtual, CPU (lavapipe). ContextOptions::device ("2" or a case-insensitive
// name substring) overrides the choice. With no usable device the constructor throws
// ort::Unsupported (core/errors.h) saying why, per device; a device that is there but fails
// to start throws std::runtime_error.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace ort::vk {

struct ContextOptions {
  std::string device;                          // index or name substring; empty: automatic
  std::vector<const char*> device_extensions;  // extra extensions the device must have (all enabled)
  bool need_float64 = true;                    // shaderFloat64 (OctoMap's double tMax/tDelta)
  bool need_int64 = false;                     // shaderInt64
  // Vulkan 1.2 features to enable (sType/pNext are set here). A back end that wants, say,
  // bufferDeviceAddress sets it; the device must support every feature set to VK_TRUE.
  VkPhysicalDeviceVulkan12Features features12{};
  // Further feature structs (e.g. acceleration-structure and ray-tracing-pipeline features),
  // chained after VkPhysicalDeviceFeatures2 -> Vulkan12Features. They are passed to
  // vkCreateDevice as given; do not put Vulkan11/12/13 feature structs here.
  void* feature_chain = nullptr;
};

struct DeviceInfo {
  uint32_t index = 0;
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  uint32_t api_version = 0;
  std::string unusable;  // empty if it meets the requirements, else why not
};

const char* device_type_name(VkPhysicalDeviceType t);

// An extension's properties of a physical device: `T` is the properties struct and `type`
// its sType (e.g. the acceleration-structure or ray-tracing-pipeline limits).
template <class T>
T extension_properties(VkPhysicalDevice device, VkStructureType type) {
  T props{};
  props.sType = type;
  VkPhysicalDeviceProperties2 chain{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &props, {}};
  vkGetPhysicalDeviceProperties2(device, &chain);
  return props;
}

// Owns VkInstance + VkDevice. Not copyable or movable. Several GPU objects can work on one
// context (a back end's GPU ray space and its shooting pipelines today, further GPU passes
// beside them): it is held by std::shared_ptr, and each object that makes Vulkan objects
// from it keeps a copy of that pointer, or is a member of one that does and is declared
// after it, so the device outlives everything made on it. Not thread-safe: the objects
// sharing it submit to its one queue from one thread.
class Context {
 public:
  explicit Context(const ContextOptions& opts);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physical_device() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  uint32_t timestamp_valid_bits() const { return timestamp_valid_bits_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  const VkPhysicalDeviceMemoryProperties& memory_properties() const { return memory_; }
  std::string device_name() const { return properties_.deviceName; }
  // Every device found, with why the unusable ones were not taken.
  const std::vector<DeviceInfo>& devices() const { return devices_; }

  // True where device-local memory is also host-visible and coherent on every heap that
  // matters (CPU devices such as lavapipe, most integrated GPUs): no staging copies needed.
  bool unified_memory() const { return unified_memory_; }
  // Size of the largest device-local heap.
  uint64_t device_local_bytes() const;
  // A memory type index allowed by type_bits with all `required` flags, preferring one that
  // also has all `preferred` flags; throws when none has the required flags.
  uint32_t find_memory_type(uint32_t type_bits, VkMemoryPropertyFlags required,
                            VkMemoryPropertyFlags preferred = 0) const;

 private:
  void create_instance();
  void choose_physical_device(const ContextOptions& opts);
  bool has_unified_memory() const;
  void create_device(const ContextOptions& opts);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  uint32_t timestamp_valid_bits_ = 0;
  bool unified_memory_ = false;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  std::vector<DeviceInfo> devices_;
};

}  // namespace ort::vk
