// The ground layer's small helpers: the log sink, the back-end name list, the clock.
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "core/backend_kind.h"
#include "core/clock.h"
#include "core/errors.h"
#include "core/log.h"

namespace ort::test {
namespace {

TEST(Log, OneMessagePerLineWithItsLevel) {
  std::vector<std::pair<LogLevel, std::string>> got;
  const Log log([&](LogLevel level, std::string_view m) { got.emplace_back(level, std::string(m)); });
  log.info("a");
  log.lines(LogLevel::kWarning, "b\n\nc\nd");
  log.error("e");
  ASSERT_EQ(got.size(), 5u);
  EXPECT_EQ(got[0], std::make_pair(LogLevel::kInfo, std::string("a")));
  EXPECT_EQ(got[1], std::make_pair(LogLevel::kWarning, std::string("b")));
  EXPECT_EQ(got[2].second, "c");
  EXPECT_EQ(got[3].second, "d");
  EXPECT_EQ(got[4], std::make_pair(LogLevel::kError, std::string("e")));
}

TEST(Log, IntoStringAndDefaultDiscards) {
  std::string text;
  const Log into = log_into(text);
  into.info("first");
  into.warning("second");
  EXPECT_EQ(text, "first\nsecond\n");
  const Log none;
  none.error("nobody listens");  // must not crash
  EXPECT_EQ(text, "first\nsecond\n");
}

TEST(BackendNames, EveryNameParsesBackToItsKind) {
  const std::vector<std::string> names = backend_names();
  ASSERT_EQ(names.front(), "auto");
  for (const std::string& n : names) {
    BackendKind k{};
    ASSERT_TRUE(parse_backend(n, k)) << n;
    EXPECT_EQ(n, to_string(k));
  }
  BackendKind k{};
  EXPECT_FALSE(parse_backend("gpu", k));
  EXPECT_EQ(names.size(), 5u);  // auto, cpu, cpu-grid, vulkan, rt
}

TEST(Unsupported, IsARuntimeErrorWithItsMessage) {
  try {
    throw Unsupported("unsupported: no device");
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "unsupported: no device");
  }
}

TEST(Clock, MillisecondsAndUtime) {
  const auto t0 = SteadyClock::now();
  std::this_thread::sleep_for(std::chrono::milliseconds(2));
  EXPECT_GE(ms_since(t0), 2.0);
  EXPECT_DOUBLE_EQ(ms_between(t0, t0 + std::chrono::microseconds(1500)), 1.5);
  EXPECT_GT(now_utime(), int64_t(1'600'000'000'000'000));  // after 2020, in microseconds
}

}  // namespace
}  // namespace ort::test
