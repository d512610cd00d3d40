// Recording and running work on the context's queue, one command buffer at a time.
#pragma once

#include <vulkan/vulkan.h>

#include "gpu/vk/vk_context.h"

namespace ort::vk {

// A command pool with one primary command buffer and a fence: begin(), record,
// submit_and_wait(). The back ends run each scan as one or two such submissions; the
// command buffer is reset and re-recorded each time (cheap next to the work it carries).
class CommandRunner {
 public:
  explicit CommandRunner(const Context& ctx);
  ~CommandRunner();
  CommandRunner(const CommandRunner&) = delete;
  CommandRunner& operator=(const CommandRunner&) = delete;

  // Resets the command buffer and begins recording (one-time submit).
  VkCommandBuffer begin();
  // Ends recording, submits, and blocks until the device has finished.
  void submit_and_wait();

 private:
  VkDevice device_;
  VkQueue queue_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
};

// A global memory barrier between two stages (shader writes -> shader reads, transfer ->
// shader, shader -> indirect-argument reads, ...).
void memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src_access,
                    VkPipelineStageFlags dst_stage, VkAccessFlags dst_access);

// Shorthand: compute-shader writes visible to compute-shader reads and writes.
inline void compute_to_compute(VkCommandBuffer cmd) {
  memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

}  // namespace ort::vk
