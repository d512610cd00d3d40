// The memory bound's working set (octree/residency/working_set_window.h) alone, on a stepped
// clock: which regions are in use, and how T follows the robots' scan rate.
#include <chrono>
#include <string>

#include <gtest/gtest.h>

#include "octree/residency/working_set_window.h"

namespace ort::test {
namespace {

using std::chrono::duration_cast;
using std::chrono::milliseconds;

// A clock the test moves by hand.
struct SteppedClock {
  WorkingSetWindow::TimePoint now{};
  void step_ms(int64_t ms) { now += duration_cast<SteadyClock::duration>(milliseconds(ms)); }
  WorkingSetWindow::Clock clock() {
    return [this] { return now; };
  }
};

// `scans` scans of `robot`, `interval_ms` apart (the first one `interval_ms` from now).
void scans_every(WorkingSetWindow& w, SteppedClock& c, const std::string& robot, int scans, int64_t interval_ms) {
  for (int i = 0; i < scans; ++i) {
    c.step_ms(interval_ms);
    w.scan(robot);
  }
}

TEST(WorkingSetWindow, AFixedWindowKeepsARegionInUseForThatLongAfterItsLastTouch) {
  SteppedClock c;
  WorkingSetWindow w(10, c.clock());
  EXPECT_FALSE(w.in_use(7)) << "never touched: idle";
  w.touch(7, w.now());
  c.step_ms(9'900);
  EXPECT_TRUE(w.in_use(7));
  w.touch(8, w.now());
  c.step_ms(100);  // 10 s after 7's touch
  EXPECT_FALSE(w.in_use(7));
  EXPECT_TRUE(w.in_use(8));
  w.touch(7, w.now());  // touched again: in use again
  EXPECT_TRUE(w.in_use(7));
  // A fixed T ignores the scan rate, however fast or slow.
  scans_every(w, c, "robot", 20, 3'000);
  EXPECT_DOUBLE_EQ(w.seconds(), 10);
  scans_every(w, c, "robot", 20, 10);
  EXPECT_DOUBLE_EQ(w.seconds(), 10);
  w.forget(8);
  EXPECT_EQ(w.last_touch(8), WorkingSetWindow::TimePoint::min());
}

TEST(WorkingSetWindow, TheAdaptiveWindowIsFiftyTimesTheSlowestRobotsScanInterval) {
  SteppedClock c;
  WorkingSetWindow w(0, c.clock());
  EXPECT_DOUBLE_EQ(w.seconds(), WorkingSetWindow::kFirstSeconds) << "no scan yet";
  w.scan("fast");
  EXPECT_DOUBLE_EQ(w.seconds(), WorkingSetWindow::kFirstSeconds) << "one scan is no rate";
  scans_every(w, c, "fast", 30, 50);  // 20 Hz: 50 x 0.05 s
  EXPECT_NEAR(w.seconds(), 2.5, 1e-9);
  // A region touched now is in use for 2.5 s of the clock.
  w.touch(1, w.now());
  c.step_ms(2'400);
  EXPECT_TRUE(w.in_use(1));
  c.step_ms(200);
  EXPECT_FALSE(w.in_use(1));

  // A second robot at 1 Hz: the slowest robot decides (50 s).
  w.scan("slow");
  EXPECT_NEAR(w.seconds(), 2.5, 1e-9) << "its first scan is no rate yet";
  for (int i = 0; i < 5; ++i) {
    scans_every(w, c, "fast", 20, 50);
    w.scan("slow");
  }
  EXPECT_NEAR(w.seconds(), 50, 1e-9);

  // The mean moves by a tenth of the newest interval: the slow robot at 2 Hz from now on.
  c.step_ms(500);
  w.scan("slow");
  EXPECT_NEAR(w.seconds(), 50 * (0.9 * 1.0 + 0.1 * 0.5), 1e-9);
  scans_every(w, c, "slow", 200, 500);
  EXPECT_NEAR(w.seconds(), 25, 1e-6);
}

TEST(WorkingSetWindow, TheAdaptiveWindowIsClampedToOneSecondAndTwoMinutes) {
  SteppedClock c;
  WorkingSetWindow w(0, c.clock());
  w.scan("lidar");
  scans_every(w, c, "lidar", 50, 5);  // 200 Hz: 50 x 5 ms = 0.25 s
  EXPECT_DOUBLE_EQ(w.seconds(), WorkingSetWindow::kMinSeconds);
  w.scan("survey");
  scans_every(w, c, "survey", 3, 10'000);  // one scan in 10 s: 500 s
  EXPECT_DOUBLE_EQ(w.seconds(), WorkingSetWindow::kMaxSeconds);
}

TEST(WorkingSetWindow, APauseIsNotCountedAsARate) {
  SteppedClock c;
  WorkingSetWindow w(0, c.clock());
  w.scan("robot");
  scans_every(w, c, "robot", 30, 50);
  ASSERT_NEAR(w.seconds(), 2.5, 1e-9);
  w.touch(3, w.now());
  // Parked for 5 minutes: the interval across the pause leaves the mean as it was.
  c.step_ms(300'000);
  w.scan("robot");
  EXPECT_NEAR(w.seconds(), 2.5, 1e-9);
  EXPECT_FALSE(w.in_use(3)) << "touched before the pause";
  scans_every(w, c, "robot", 10, 50);
  EXPECT_NEAR(w.seconds(), 2.5, 1e-9);
  // A robot back after a pause counts from its next scan: a first interval past the pause
  // bound is no rate either.
  w.scan("late");
  c.step_ms(121'000);
  w.scan("late");
  EXPECT_NEAR(w.seconds(), 2.5, 1e-9);
  c.step_ms(100'000);  // within the bound: a slow robot, 100 s a scan
  w.scan("late");
  EXPECT_DOUBLE_EQ(w.seconds(), WorkingSetWindow::kMaxSeconds);
}

TEST(WorkingSetWindow, AtMostTheSourceCapIsKeptTheOldestGoingFirst) {
  SteppedClock c;
  WorkingSetWindow w(0, c.clock());
  w.scan("slow");
  c.step_ms(2'000);
  w.scan("slow");  // 2 s a scan: T = 100 s
  ASSERT_NEAR(w.seconds(), 100, 1e-9);
  // As many new robot ids as the cap, each heard once, all after "slow"'s last scan.
  for (size_t i = 0; i + 1 < WorkingSetWindow::kMaxSources; ++i) {
    c.step_ms(1);
    w.scan("robot-" + std::to_string(i));
  }
  EXPECT_EQ(w.sources(), WorkingSetWindow::kMaxSources);
  EXPECT_NEAR(w.seconds(), 100, 1e-9) << "within the cap every source is kept";
  c.step_ms(1);
  w.scan("one-more");
  EXPECT_EQ(w.sources(), WorkingSetWindow::kMaxSources);
  EXPECT_DOUBLE_EQ(w.seconds(), WorkingSetWindow::kFirstSeconds)
      << "the source heard from longest ago (the slow robot, its rate with it) went";
  // The robot that went comes back as a new source: one scan, no rate yet.
  c.step_ms(1);
  w.scan("slow");
  EXPECT_EQ(w.sources(), WorkingSetWindow::kMaxSources);
  EXPECT_DOUBLE_EQ(w.seconds(), WorkingSetWindow::kFirstSeconds);
}

}  // namespace
}  // namespace ort::test
