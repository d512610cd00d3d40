// The VK_KHR_acceleration_structure / VK_KHR_ray_tracing_pipeline entry points. The Vulkan
// loader does not export extension commands, so they are fetched once per device.
#pragma once

#include <vulkan/vulkan.h>

namespace ort::rt {

struct RtFunctions {
  PFN_vkCreateAccelerationStructureKHR create_acceleration_structure = nullptr;
  PFN_vkDestroyAccelerationStructureKHR destroy_acceleration_structure = nullptr;
  PFN_vkGetAccelerationStructureBuildSizesKHR get_build_sizes = nullptr;
  PFN_vkGetAccelerationStructureDeviceAddressKHR get_acceleration_structure_address = nullptr;
  PFN_vkCmdBuildAccelerationStructuresKHR cmd_build_acceleration_structures = nullptr;
  PFN_vkCreateRayTracingPipelinesKHR create_ray_tracing_pipelines = nullptr;
  PFN_vkGetRayTracingShaderGroupHandlesKHR get_shader_group_handles = nullptr;
  PFN_vkCmdTraceRaysKHR cmd_trace_rays = nullptr;
};

// Throws std::runtime_error naming the first entry point the driver does not give.
RtFunctions load_rt_functions(VkDevice device);

// The device's VK_KHR_acceleration_structure limits (instance count, scratch alignment).
VkPhysicalDeviceAccelerationStructurePropertiesKHR acceleration_structure_properties(VkPhysicalDevice device);

}  // namespace ort::rt
