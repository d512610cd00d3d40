// Turning Vulkan result codes into exceptions with a message that says what failed.
#pragma once

#include <vulkan/vulkan.h>

namespace ort::vk {

// The enumerator's name, e.g. "VK_ERROR_OUT_OF_DEVICE_MEMORY".
const char* result_name(VkResult r);

// Throws std::runtime_error("<what>: <result name>") unless r is VK_SUCCESS.
void check(VkResult r, const char* what);

}  // namespace ort::vk
