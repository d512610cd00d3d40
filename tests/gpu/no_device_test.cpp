// With no Vulkan driver at all (the loader pointed at a driver file that does not exist),
// the vulkan back end says so clearly and the automatic choice falls back to the native walk (cpu-grid).
// Its own program: the loader must not have been used before the environment is set.
#include <cstdlib>
#include <stdexcept>

#include <gtest/gtest.h>

#include "engine/backend_factory.h"

namespace ort::test {
namespace {

TEST(NoVulkanDevice, ClearErrorAndCpuGridFallback) {
  setenv("VK_ICD_FILENAMES", "/nonexistent/octomap-rt-no-driver.json", 1);
  setenv("VK_DRIVER_FILES", "/nonexistent/octomap-rt-no-driver.json", 1);
  BackendOptions o;
  o.kind = BackendKind::kVulkan;
  try {
    make_backend(o);
    FAIL() << "a vulkan back end was made without a driver";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no Vulkan device"), std::string::npos) << e.what();
  }
  o.kind = BackendKind::kAuto;
  std::string log;
  o.grid_budget_bytes = 1 << 20;
  auto b = make_backend(o, log_into(log));
  EXPECT_EQ(b->kind(), BackendKind::kCpuGrid);
  EXPECT_NE(log.find("no Vulkan device"), std::string::npos) << log;
  EXPECT_NE(log.find("using cpu-grid"), std::string::npos) << log;
}

}  // namespace
}  // namespace ort::test
