#include "gpu/vk/vk_timestamps.h"

#include "gpu/vk/vk_check.h"

namespace ort::vk {

TimestampQueries::TimestampQueries(const Context& ctx, uint32_t count)
    : device_(ctx.device()),
      count_(count),
      ns_per_tick_(ctx.properties().limits.timestampPeriod),
      mask_(ctx.timestamp_valid_bits() >= 64 ? ~0ull : ((1ull << ctx.timestamp_valid_bits()) - 1)),
      values_(count, 0) {
  if (ctx.timestamp_valid_bits() == 0 || ns_per_tick_ <= 0) return;
  VkQueryPoolCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  ci.queryType = VK_QUERY_TYPE_TIMESTAMP;
  ci.queryCount = count;
  if (vkCreateQueryPool(device_, &ci, nullptr, &pool_) != VK_SUCCESS) pool_ = VK_NULL_HANDLE;
}

TimestampQueries::~TimestampQueries() {
  if (pool_) vkDestroyQueryPool(device_, pool_, nullptr);
}

void TimestampQueries::reset(VkCommandBuffer cmd) {
  if (pool_) vkCmdResetQueryPool(cmd, pool_, 0, count_);
}

void TimestampQueries::write(VkCommandBuffer cmd, uint32_t index, VkPipelineStageFlagBits stage) {
  if (pool_) vkCmdWriteTimestamp(cmd, stage, pool_, index);
}

void TimestampQueries::fetch(uint32_t count) {
  if (!pool_ || count == 0) return;
  check(vkGetQueryPoolResults(device_, pool_, 0, count, count * sizeof(uint64_t), values_.data(), sizeof(uint64_t),
                              VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "vkGetQueryPoolResults");
}

double TimestampQueries::elapsed_ms(uint32_t from, uint32_t to) const {
  if (!pool_) return 0.0;
  const uint64_t ticks = (values_[to] - values_[from]) & mask_;
  return double(ticks) * ns_per_tick_ * 1e-6;
}

}  // namespace ort::vk
