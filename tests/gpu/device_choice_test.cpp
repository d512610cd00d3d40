// Vulkan device choice: automatic (discrete, integrated, then CPU device), by index, by a
// case-insensitive name substring; clear errors for devices that do not exist or lack what
// is required; the factory's fallback to cpu.
#include <algorithm>
#include <cctype>
#include <stdexcept>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "engine/backend_factory.h"
#include "gpu/vk/vk_context.h"
#include "gpu/vulkan_backend.h"

namespace ort::test {
namespace {

std::string error_of(const vk::ContextOptions& o) {
  try {
    vk::Context ctx(o);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(DeviceChoice, AutomaticPicksTheBestTypeThatQualifies) {
  vk::Context ctx{vk::ContextOptions{}};
  ASSERT_FALSE(ctx.devices().empty());
  int best_rank = 99, chosen_rank = 99;
  auto rank = [](VkPhysicalDeviceType t) {
    return t == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU     ? 0
           : t == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU ? 1
           : t == VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU    ? 2
           : t == VK_PHYSICAL_DEVICE_TYPE_CPU            ? 3
                                                         : 4;
  };
  for (const vk::DeviceInfo& d : ctx.devices()) {
    std::printf("device %u: %s (%s) %s\n", d.index, d.name.c_str(), vk::device_type_name(d.type),
                d.unusable.empty() ? "usable" : d.unusable.c_str());
    if (d.unusable.empty()) best_rank = std::min(best_rank, rank(d.type));
    if (d.name == ctx.device_name()) chosen_rank = rank(d.type);
  }
  EXPECT_EQ(chosen_rank, best_rank);
  EXPECT_GE(ctx.properties().apiVersion, VK_API_VERSION_1_2);
}

TEST(DeviceChoice, ByIndexAndByNameSubstring) {
  vk::Context automatic{vk::ContextOptions{}};
  uint32_t index = 0;
  for (const vk::DeviceInfo& d : automatic.devices()) {
    if (d.name == automatic.device_name()) index = d.index;
  }
  vk::ContextOptions by_index;
  by_index.device = std::to_string(index);
  EXPECT_EQ(vk::Context(by_index).device_name(), automatic.device_name());

  // A middle part of the name, in the other case.
  std::string part = automatic.device_name().substr(1, std::min<size_t>(6, automatic.device_name().size() - 1));
  for (char& c : part)
    c = std::isupper((unsigned char)c) ? char(std::tolower((unsigned char)c)) : char(std::toupper((unsigned char)c));
  vk::ContextOptions by_name;
  by_name.device = part;
  EXPECT_EQ(vk::Context(by_name).device_name(), automatic.device_name()) << part;
}

TEST(DeviceChoice, ClearErrors) {
  vk::ContextOptions o;
  o.device = "no-such-gpu-4711";
  EXPECT_NE(error_of(o).find("no Vulkan device matches 'no-such-gpu-4711'"), std::string::npos) << error_of(o);
  o.device = "99";
  EXPECT_NE(error_of(o).find("no Vulkan device with index 99"), std::string::npos) << error_of(o);
  o.device.clear();
  o.device_extensions = {"VK_ORT_not_an_extension"};
  EXPECT_NE(error_of(o).find("lacks VK_ORT_not_an_extension"), std::string::npos) << error_of(o);
}

TEST(DeviceChoice, FactoryHonoursDeviceAndFallsBackToCpuGridOnlyInAuto) {
  BackendOptions o;
  o.kind = BackendKind::kVulkan;
  o.grid_budget_bytes = 1 << 20;
  o.device = "no-such-gpu-4711";
  EXPECT_THROW(make_backend(o), Unsupported);  // the typed refusal: the one kAuto moves on after
  o.kind = BackendKind::kAuto;
  std::string log;
  auto b = make_backend(o, log_into(log));
  EXPECT_EQ(b->kind(), BackendKind::kCpuGrid);
  EXPECT_NE(log.find("no-such-gpu-4711"), std::string::npos) << log;
  o.kind = BackendKind::kVulkan;
  o.device.clear();
  log.clear();
  auto v = make_backend(o, log_into(log));
  EXPECT_EQ(v->kind(), BackendKind::kVulkan);
  EXPECT_FALSE(v->device_name().empty());
  EXPECT_NE(log.find(v->device_name()), std::string::npos) << log;
}

// Automatic choice on a CPU Vulkan device (lavapipe, as in CI): the native walk instead,
// saying why; on a GPU: a GPU back end.
TEST(DeviceChoice, AutoTakesTheNativeWalkInsteadOfACpuVulkanDevice) {
  BackendOptions o;
  o.kind = BackendKind::kAuto;
  o.grid_budget_bytes = 1 << 20;
  std::string log;
  auto b = make_backend(o, log_into(log));
  const bool cpu_device = vk::Context(vk::ContextOptions{}).properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  if (cpu_device) {
    EXPECT_EQ(b->kind(), BackendKind::kCpuGrid);
    EXPECT_NE(log.find("the Vulkan device is a CPU implementation"), std::string::npos) << log;
  } else {
    EXPECT_TRUE(b->kind() == BackendKind::kVulkan || b->kind() == BackendKind::kRt) << log;
  }
}

// `auto` moves on only after a typed refusal. rt refuses --traversal octomap (Unsupported)
// on every device; on a GPU the vulkan back end then fails for a reason that is not a refusal
// (a grid budget that holds no voxel), and that failure must surface instead of a silent
// fallback. (On a CPU Vulkan device auto does not try vulkan at all: nothing to check there.)
TEST(DeviceChoice, AutoFallsBackOnlyOnUnsupported) {
  if (vk::Context(vk::ContextOptions{}).properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) {
    GTEST_SKIP() << "the Vulkan device is a CPU implementation: auto takes cpu-grid without trying vulkan";
  }
  BackendOptions o;
  o.kind = BackendKind::kAuto;
  o.traversal = Traversal::kOctomap;
  o.grid_budget_bytes = 3;
  std::string log;
  EXPECT_THROW(make_backend(o, log_into(log)), std::invalid_argument);
  EXPECT_NE(log.find("rt back end not used: unsupported"), std::string::npos) << log;
  EXPECT_EQ(log.find("using cpu"), std::string::npos) << log;
}

}  // namespace
}  // namespace ort::test
