// GPU timestamps around stages of a submission (the device's own clock, for stage times
// that do not include host wake-up latency).
#pragma once

#include <cstdint>
#include <vector>

#include <vulkan/vulkan.h>

#include "gpu/vk/vk_context.h"

namespace ort::vk {

class TimestampQueries {
 public:
  TimestampQueries(const Context& ctx, uint32_t count);
  ~TimestampQueries();
  TimestampQueries(const TimestampQueries&) = delete;
  TimestampQueries& operator=(const TimestampQueries&) = delete;

  // False where the queue cannot write timestamps; then write() does nothing and
  // elapsed_ms() returns 0.
  bool supported() const { return pool_ != VK_NULL_HANDLE; }
  // Record at the start of a command buffer, before any write().
  void reset(VkCommandBuffer cmd);
  void write(VkCommandBuffer cmd, uint32_t index, VkPipelineStageFlagBits stage = VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  // After the submission has finished: fetches the values written since reset().
  void fetch(uint32_t count);
  // Milliseconds between two fetched timestamps.
  double elapsed_ms(uint32_t from, uint32_t to) const;

 private:
  VkDevice device_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  uint32_t count_;
  double ns_per_tick_;
  uint64_t mask_;
  std::vector<uint64_t> values_;
};

}  // namespace ort::vk
