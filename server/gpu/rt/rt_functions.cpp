#include "gpu/rt/rt_functions.h"

#include <stdexcept>
#include <string>

#include "core/errors.h"
#include "gpu/vk/vk_context.h"

namespace ort::rt {

RtFunctions load_rt_functions(VkDevice device) {
  RtFunctions f;
  auto load = [&](auto& fn, const char* name) {
    fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(vkGetDeviceProcAddr(device, name));
    if (!fn) throw Unsupported(std::string("unsupported: the Vulkan driver gives no ") + name);
  };
  load(f.create_acceleration_structure, "vkCreateAccelerationStructureKHR");
  load(f.destroy_acceleration_structure, "vkDestroyAccelerationStructureKHR");
  load(f.get_build_sizes, "vkGetAccelerationStructureBuildSizesKHR");
  load(f.get_acceleration_structure_address, "vkGetAccelerationStructureDeviceAddressKHR");
  load(f.cmd_build_acceleration_structures, "vkCmdBuildAccelerationStructuresKHR");
  load(f.create_ray_tracing_pipelines, "vkCreateRayTracingPipelinesKHR");
  load(f.get_shader_group_handles, "vkGetRayTracingShaderGroupHandlesKHR");
  load(f.cmd_trace_rays, "vkCmdTraceRaysKHR");
  return f;
}

VkPhysicalDeviceAccelerationStructurePropertiesKHR acceleration_structure_properties(VkPhysicalDevice device) {
  return vk::extension_properties<VkPhysicalDeviceAccelerationStructurePropertiesKHR>(
      device, VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR);
}

}  // namespace ort::rt
