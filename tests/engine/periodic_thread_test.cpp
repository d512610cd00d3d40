// The daemon's periodic loops (saves, status, upkeep, the viewer map, deltas, the grid) run
// on core's PeriodicThread: a stop ends the wait at once whatever the period, wake() runs the
// task now, and the options say whether a run comes first and whether a last one follows the
// stop. Periods here are a minute, so every "at once" below is a minute early if it breaks.
#include <atomic>
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "core/clock.h"
#include "core/threads/periodic_thread.h"

namespace ort::test {
namespace {

constexpr double kMinute = 60;

// Waits up to 10 s for `n` runs.
bool reaches(const std::atomic<int>& runs, int n) {
  const auto deadline = SteadyClock::now() + std::chrono::seconds(10);
  while (runs < n && SteadyClock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return runs >= n;
}

TEST(PeriodicThread, AStopEndsTheWaitAtOnceWithoutARun) {
  std::atomic<int> runs{0};
  PeriodicThread t;
  t.start(kMinute, [&] { runs++; });
  EXPECT_TRUE(t.running());
  const auto t0 = SteadyClock::now();
  t.stop();
  EXPECT_LT(seconds_since(t0), 10.0);
  EXPECT_FALSE(t.running());
  EXPECT_EQ(runs, 0);
  t.stop();  // idempotent
  t.start(
      kMinute, [&] { runs++; }, PeriodicOptions{true, true, false});
  EXPECT_FALSE(t.running()) << "a start after the stop starts nothing";
}

TEST(PeriodicThread, RunsFirstAndOnStopWhenAsked) {
  std::atomic<int> runs{0};
  PeriodicThread t;
  PeriodicOptions o;
  o.run_first = true;
  o.run_on_stop = true;
  t.start(
      kMinute, [&] { runs++; }, o);
  ASSERT_TRUE(reaches(runs, 1));
  t.stop();
  EXPECT_EQ(runs, 2);  // the first run and the last: none waited a period
}

TEST(PeriodicThread, AWakeRunsTheTaskNow) {
  std::atomic<int> runs{0};
  PeriodicThread t;
  t.wake();  // before the start: the first wait ends at once (a state set before the status runs)
  t.start(kMinute, [&] { runs++; });
  ASSERT_TRUE(reaches(runs, 1));
  t.wake();
  ASSERT_TRUE(reaches(runs, 2));
  t.stop();
  EXPECT_EQ(runs, 2);
}

TEST(PeriodicThread, RunsEveryPeriod) {
  for (const bool fixed_rate : {false, true}) {
    std::atomic<int> runs{0};
    PeriodicThread t;
    PeriodicOptions o;
    o.fixed_rate = fixed_rate;
    t.start(
        0.005, [&] { runs++; }, o);
    EXPECT_TRUE(reaches(runs, 5)) << fixed_rate;
  }
}

TEST(PeriodicThread, APauseInsideTheTaskEndsWithTheStop) {
  std::atomic<int> runs{0};
  std::atomic<bool> paused_through{true};
  PeriodicThread t;
  PeriodicOptions o;
  o.run_first = true;
  t.start(
      kMinute,
      [&] {
        runs++;
        paused_through = t.pause(std::chrono::minutes(1));
      },
      o);
  ASSERT_TRUE(reaches(runs, 1));
  const auto t0 = SteadyClock::now();
  t.stop();
  EXPECT_LT(seconds_since(t0), 10.0);
  EXPECT_FALSE(paused_through);
  EXPECT_FALSE(t.pause(std::chrono::milliseconds(0))) << "stopped: a pause says so at once";
}

}  // namespace
}  // namespace ort::test
