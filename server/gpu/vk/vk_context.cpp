#include "gpu/vk/vk_context.h"

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <cstring>
#include <stdexcept>

#include "core/errors.h"
#include "gpu/vk/vk_check.h"

namespace ort::vk {
namespace {

// Lower rank = preferred.
int type_rank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower((unsigned char)c));
  return s;
}

bool all_digits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit((unsigned char)c); });
}

// The VkBool32 members of VkPhysicalDeviceVulkan12Features, as an array (they follow
// sType/pNext contiguously), so requested features can be checked one by one.
constexpr size_t kFirst12 = offsetof(VkPhysicalDeviceVulkan12Features, samplerMirrorClampToEdge);
constexpr size_t kCount12 = (sizeof(VkPhysicalDeviceVulkan12Features) - kFirst12) / sizeof(VkBool32);
const VkBool32* bools12(const VkPhysicalDeviceVulkan12Features& f) {
  return reinterpret_cast<const VkBool32*>(reinterpret_cast<const char*>(&f) + kFirst12);
}

// A compute queue family, preferring one that can write timestamps.
int pick_queue_family(VkPhysicalDevice pd, uint32_t* timestamp_bits) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> q(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, q.data());
  int best = -1;
  for (uint32_t i = 0; i < n; ++i) {
    if (!(q[i].queueFlags & VK_QUEUE_COMPUTE_BIT) || q[i].queueCount == 0) continue;
    if (best < 0 || (q[best].timestampValidBits == 0 && q[i].timestampValidBits > 0)) best = int(i);
  }
  if (best >= 0 && timestamp_bits) *timestamp_bits = q[best].timestampValidBits;
  return best;
}

// Why this device cannot be used ("" = it can).
std::string check_device(VkPhysicalDevice pd, const ContextOptions& opts) {
  VkPhysicalDeviceProperties p;
  vkGetPhysicalDeviceProperties(pd, &p);
  if (p.apiVersion < VK_API_VERSION_1_2) return "Vulkan 1.2 is required";
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> ext(n);
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, ext.data());
  std::string missing;
  for (const char* want : opts.device_extensions) {
    const bool have = std::any_of(ext.begin(), ext.end(), [&](const VkExtensionProperties& e) {
      return std::strcmp(e.extensionName, want) == 0;
    });
    if (!have) missing += std::string(missing.empty() ? "" : ", ") + want;
  }
  if (!missing.empty()) return "lacks " + missing;

  VkPhysicalDeviceVulkan12Features f12{};
  f12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
  VkPhysicalDeviceFeatures2 f2{};
  f2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
  f2.pNext = &f12;
  vkGetPhysicalDeviceFeatures2(pd, &f2);
  if (opts.need_float64 && !f2.features.shaderFloat64) return "lacks shaderFloat64";
  if (opts.need_int64 && !f2.features.shaderInt64) return "lacks shaderInt64";
  const VkBool32* want = bools12(opts.features12);
  const VkBool32* have = bools12(f12);
  for (size_t i = 0; i < kCount12; ++i) {
    if (want[i] && !have[i]) return "lacks a requested Vulkan 1.2 feature (member " + std::to_string(i) + ")";
  }
  if (pick_queue_family(pd, nullptr) < 0) return "has no compute queue";
  return "";
}

}  // namespace

const char* device_type_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU device";
    default: return "other device";
  }
}

namespace {

std::string describe_devices(const std::vector<DeviceInfo>& devices) {
  std::string s;
  for (const DeviceInfo& d : devices) {
    s += "\n  [" + std::to_string(d.index) + "] " + d.name + " (" + device_type_name(d.type) +
         "): " + (d.unusable.empty() ? "usable" : d.unusable);
  }
  return s;
}

// The index of the device to take: the best usable type when `wanted` is empty, else the
// device of that index or the first usable one whose name contains it (any case). Throws
// saying why, per device, when there is none.
int choose_device(const std::vector<DeviceInfo>& devices, const std::string& wanted) {
  int chosen = -1;
  if (wanted.empty()) {
    for (const DeviceInfo& d : devices) {
      if (!d.unusable.empty()) continue;
      if (chosen < 0 || type_rank(d.type) < type_rank(devices[chosen].type)) chosen = int(d.index);
    }
    if (chosen < 0) throw Unsupported("no usable Vulkan device:" + describe_devices(devices));
    return chosen;
  }
  if (all_digits(wanted)) {
    const unsigned long idx = std::stoul(wanted);
    if (idx >= devices.size())
      throw Unsupported("no Vulkan device with index " + wanted + ":" + describe_devices(devices));
    if (!devices[idx].unusable.empty())
      throw Unsupported("Vulkan device " + wanted + " (" + devices[idx].name + ") " + devices[idx].unusable);
    return int(idx);
  }
  const std::string name = lower(wanted);
  bool matched = false;
  for (const DeviceInfo& d : devices) {
    if (lower(d.name).find(name) == std::string::npos) continue;
    matched = true;
    if (d.unusable.empty()) return int(d.index);
  }
  throw Unsupported((matched ? "no usable Vulkan device matches '" : "no Vulkan device matches '") + wanted +
                    "':" + describe_devices(devices));
}

}  // namespace

Context::Context(const ContextOptions& opts) {
  create_instance();
  try {
    choose_physical_device(opts);
    create_device(opts);
  } catch (...) {
    if (device_) vkDestroyDevice(device_, nullptr);
    vkDestroyInstance(instance_, nullptr);
    throw;
  }
}

void Context::create_instance() {
  uint32_t loader_version = 0;
  if (vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS || loader_version < VK_API_VERSION_1_2) {
    throw Unsupported("no Vulkan device: the Vulkan loader does not support Vulkan 1.2");
  }
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "octomap-rt";
  app.pEngineName = "octomap-rt";
  app.apiVersion = VK_API_VERSION_1_2;
  VkInstanceCreateInfo ici{};
  ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ici.pApplicationInfo = &app;
  const VkResult ir = vkCreateInstance(&ici, nullptr, &instance_);
  if (ir != VK_SUCCESS) {
    instance_ = VK_NULL_HANDLE;
    throw Unsupported(std::string("no Vulkan device: vkCreateInstance failed (") + result_name(ir) +
                      "); is a Vulkan driver installed?");
  }
}

void Context::choose_physical_device(const ContextOptions& opts) {
  uint32_t n = 0;
  vkEnumeratePhysicalDevices(instance_, &n, nullptr);
  std::vector<VkPhysicalDevice> pds(n);
  if (n) vkEnumeratePhysicalDevices(instance_, &n, pds.data());
  if (n == 0) throw Unsupported("no Vulkan device found");
  for (uint32_t i = 0; i < n; ++i) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(pds[i], &p);
    devices_.push_back({i, p.deviceName, p.deviceType, p.apiVersion, check_device(pds[i], opts)});
  }
  physical_ = pds[choose_device(devices_, opts.device)];
  vkGetPhysicalDeviceProperties(physical_, &properties_);
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
  queue_family_ = uint32_t(pick_queue_family(physical_, &timestamp_valid_bits_));
  unified_memory_ = has_unified_memory();
}

// Unified memory: a CPU or integrated device whose largest device-local heap is also
// host-visible and coherent; buffers are then written and read in place.
bool Context::has_unified_memory() const {
  if (properties_.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU &&
      properties_.deviceType != VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU) {
    return false;
  }
  const VkMemoryPropertyFlags want =
      VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
    if ((memory_.memoryTypes[i].propertyFlags & want) == want &&
        memory_.memoryHeaps[memory_.memoryTypes[i].heapIndex].size == device_local_bytes()) {
      return true;
    }
  }
  return false;
}

void Context::create_device(const ContextOptions& opts) {
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{};
  qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  qci.queueFamilyIndex = queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkPhysicalDeviceVulkan12Features f12 = opts.features12;
  f12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
  f12.pNext = opts.feature_chain;
  VkPhysicalDeviceFeatures2 f2{};
  f2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
  f2.pNext = &f12;
  f2.features.shaderFloat64 = opts.need_float64 ? VK_TRUE : VK_FALSE;
  f2.features.shaderInt64 = opts.need_int64 ? VK_TRUE : VK_FALSE;
  VkDeviceCreateInfo dci{};
  dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  dci.pNext = &f2;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = uint32_t(opts.device_extensions.size());
  dci.ppEnabledExtensionNames = opts.device_extensions.data();
  const VkResult dr = vkCreateDevice(physical_, &dci, nullptr, &device_);
  if (dr != VK_SUCCESS) {
    device_ = VK_NULL_HANDLE;
    throw std::runtime_error(std::string("vkCreateDevice on ") + properties_.deviceName +
                             " failed: " + result_name(dr));
  }
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
}

Context::~Context() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    vkDestroyDevice(device_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

uint64_t Context::device_local_bytes() const {
  uint64_t best = 0;
  for (uint32_t i = 0; i < memory_.memoryHeapCount; ++i) {
    if (memory_.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      best = std::max<uint64_t>(best, memory_.memoryHeaps[i].size);
  }
  return best;
}

uint32_t Context::find_memory_type(uint32_t type_bits, VkMemoryPropertyFlags required,
                                   VkMemoryPropertyFlags preferred) const {
  int fallback = -1;
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
    if (!(type_bits & (1u << i))) continue;
    const VkMemoryPropertyFlags f = memory_.memoryTypes[i].propertyFlags;
    if ((f & required) != required) continue;
    if ((f & preferred) == preferred) return i;
    if (fallback < 0) fallback = int(i);
  }
  if (fallback < 0) throw std::runtime_error("no Vulkan memory type with the required properties");
  return uint32_t(fallback);
}

}  // namespace ort::vk
