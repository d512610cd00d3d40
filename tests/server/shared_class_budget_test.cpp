// The shared class's budget while a robot with history streams (intake/shared_class_budget.h),
// on its own with an injected clock: its stage time per second (a floor plus the robots' time,
// up to a burst), its per-scan bound (a floor or a multiple of the robots' mean scan), the
// refusal of a scan whose cost is not known (its rays longer than any applied), and in the
// queue: deferred while its budget is spent and a robot streams, served again once refilled
// or once no robot streams.
#include "daemon/intake/shared_class_budget.h"

#include <chrono>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "daemon/intake/scan_queue.h"

namespace ort::daemon {
namespace {

using std::chrono::milliseconds;

SteadyClock::time_point at_ms(int64_t ms) { return SteadyClock::time_point(milliseconds(1'000'000 + ms)); }

SharedClassBounds bounds() {
  SharedClassBounds b;
  b.floor_ms_per_s = 50;
  b.robot_ratio = 1.0;
  b.burst_ms = 500;
  b.scan_floor_ms = 20;
  b.scan_ratio = 4;
  return b;
}

TEST(SharedClassBudget, FullAtFirstSightThenSpentByWhatItsScansTook) {
  SharedClassBudget b(bounds());
  EXPECT_TRUE(b.may_serve(at_ms(0)));
  EXPECT_DOUBLE_EQ(b.tokens_ms(), 500);
  b.shared_used(450);
  EXPECT_TRUE(b.may_serve(at_ms(0)));
  b.shared_used(100);  // -50: spent
  EXPECT_FALSE(b.may_serve(at_ms(0)));
  EXPECT_FALSE(b.may_serve(at_ms(999)));  // the floor refills 50 ms a second: -0.05 ms left
  EXPECT_TRUE(b.may_serve(at_ms(1000)));
}

TEST(SharedClassBudget, RefillsWithTheRobotsStageTimeUpToTheBurst) {
  SharedClassBudget b(bounds());
  ASSERT_TRUE(b.may_serve(at_ms(0)));
  b.shared_used(700);  // -200
  b.robots_used(120);
  b.robots_used(60);
  EXPECT_FALSE(b.may_serve(at_ms(200)));  // -200 + 10 (floor) + 180 (robots) = -10
  EXPECT_NEAR(b.tokens_ms(), -10, 1e-9);
  b.robots_used(10);
  EXPECT_TRUE(b.may_serve(at_ms(200)));  // the robots' time counts at once, not only over time
  b.robots_used(100'000);
  EXPECT_TRUE(b.may_serve(at_ms(300)));
  EXPECT_DOUBLE_EQ(b.tokens_ms(), 500);  // no more than the burst saved
  // Time that does not pass (or a clock read out of order) refills nothing.
  b.shared_used(600);
  EXPECT_FALSE(b.may_serve(at_ms(100)));
  EXPECT_NEAR(b.tokens_ms(), -100, 1e-9);
}

TEST(SharedClassBudget, AScanBoundOfAFloorOrAMultipleOfTheRobotsMeanScan) {
  SharedClassBudget b(bounds());
  EXPECT_DOUBLE_EQ(b.scan_bound_ms(3), 20);  // no scan applied yet: the floor
  b.scan_done(0, 2, true);
  EXPECT_DOUBLE_EQ(b.scan_bound_ms(3), 20);  // 4 x 2 ms is below the floor
  b.scan_done(0, 0, true);                   // not a time: ignored
  b.scan_done(0, -5, true);
  b.scan_done(0, std::nan(""), true);
  EXPECT_DOUBLE_EQ(b.scan_bound_ms(3), 20);
  SharedClassBudget slow(bounds());
  slow.scan_done(0, 100, true);
  EXPECT_DOUBLE_EQ(slow.scan_bound_ms(3), 400);
  slow.scan_done(0, 20, true);  // an eighth of the newest: 90
  EXPECT_DOUBLE_EQ(slow.scan_bound_ms(3), 360);
  slow.scan_done(3, 5000, false);  // a shared-class scan: the robots' mean stays the scale
  EXPECT_DOUBLE_EQ(slow.scan_bound_ms(3), 360);
  // Before any robot has history, each producer's own applied scans are: a far scan applied
  // alone does not open the bound for every other fresh id.
  SharedClassBudget early(bounds());
  early.scan_done(1, 10, false);
  early.scan_done(2, 650, false);
  EXPECT_DOUBLE_EQ(early.scan_bound_ms(1), 40);
  EXPECT_DOUBLE_EQ(early.scan_bound_ms(2), 2600);
  EXPECT_DOUBLE_EQ(early.scan_bound_ms(9), 40);  // no scan of its own yet: the cheapest producer's
}

TEST(SharedClassBudget, RefusesAScanPredictedPastItsBoundOrOfUnknownCost) {
  SharedClassBudget b(bounds());
  b.scan_done(0, 10, true);  // the bound: 40 ms
  EXPECT_EQ(b.refusal(1, {30, true}, 400'000, 50, 64), "");
  EXPECT_NE(b.refusal(1, {650, true}, 400'000, 4000, 4096).find("predicted to take 650 ms"), std::string::npos);
  EXPECT_NE(b.refusal(1, {650, true}, 400'000, 4000, 4096).find("above 40 ms"), std::string::npos);
  // Not learned: its rays decide. Above 512 voxels and 4x the longest shape applied: unknown.
  EXPECT_NE(b.refusal(1, {1, false}, 400'000, 4000, 64).find("not known"), std::string::npos);
  EXPECT_NE(b.refusal(1, {}, 400'000, 4000, 0).find("above 512"), std::string::npos);  // nothing applied yet
  EXPECT_EQ(b.refusal(1, {1, false}, 400'000, 500, 64), "");                           // a robot's rays: borrowed
  EXPECT_EQ(b.refusal(1, {1, false}, 400'000, 1000, 256), "");  // within 4x a campus robot's shape
  EXPECT_NE(b.refusal(1, {1, false}, 400'000, 1100, 256).find("above 1024"), std::string::npos);
  EXPECT_EQ(b.refusal(1, {1, false}, 400'000, std::nan(""), 64), "");  // no ray length: the intake's bounds decide
  EXPECT_EQ(b.refusal(1, {1, false}, 60'000, 3000, 64), "");  // 20 long-range points: cheap whatever their space
  SharedClassBudget off(SharedClassBounds::off());
  EXPECT_EQ(off.refusal(1, {650, true}, 400'000, 4000, 4096), "");
  EXPECT_EQ(off.refusal(1, {1, false}, 400'000, 4000, 64), "");
  off.shared_used(1e9);
  EXPECT_TRUE(off.may_serve(at_ms(0)));
}

// What made the first far scan's cost look small: nothing of its shape had run, and the nearest
// learned shape was a robot's short rays through mapped space.
TEST(StageCostModel, SaysTheLongestShapeLearned) {
  StageCostModel m;
  EXPECT_EQ(m.longest_learned_ray_voxels(), 0);
  m.learn(2'000'000, 50, 5);  // a robot's scan: 5 ms, shape 32-64
  EXPECT_EQ(m.longest_learned_ray_voxels(), 64);
  const auto far = m.predict(400'000, 4000);
  EXPECT_FALSE(far.learned);
  EXPECT_NEAR(far.ms, 1, 1e-9);  // 400 000 voxels at the robot's rate: far below what it takes
  m.learn(800'000, 8000, 1300);
  EXPECT_EQ(m.longest_learned_ray_voxels(), 8192);
  m.learn(1000, 1, 1);  // a shorter shape changes nothing
  EXPECT_EQ(m.longest_learned_ray_voxels(), 8192);
}

QueuedScan queued(size_t producer, bool established, double walk, double mean) {
  QueuedScan s;
  s.producer = producer;
  s.established = established;
  s.bytes = 100;
  s.received = SteadyClock::now();
  s.walk_voxels = walk;
  s.mean_ray_voxels = mean;
  return s;
}

void run_whole(ScanQueue& q, QueuedScan s, double ms) {
  ASSERT_TRUE(q.try_push(std::move(s)));
  auto served = q.pop();
  ASSERT_TRUE(served);
  q.charge(served->arrival, ms);
  q.leave(served->arrival, true);
}

// In the queue (its own clock: a robot served within kStreamingWindow streams): a fresh id's
// scan of rays far longer than any applied is marked refused while a robot streams; once the
// shared class's budget is spent, a robot's later scan goes first and the shared class waits.
TEST(SharedClassBudget, InTheQueueAFarScanIsRefusedAndASpentClassWaitsWhileARobotStreams) {
  ScanQueue q(1 << 20, 8 << 20, true, kSharedClassShare, bounds());
  run_whole(q, queued(0, true, 2'000'000, 50), 10);  // the robot: 10 ms a scan, so 40 ms a shared scan
  ASSERT_TRUE(q.try_push(queued(5, false, 400'000, 4000)));
  auto far = q.pop();
  ASSERT_TRUE(far);
  EXPECT_FALSE(far->predicted.learned);
  EXPECT_NE(far->shared_refusal.find("not known"), std::string::npos);
  q.charge(far->arrival, 0.1);  // refused before it was shot
  q.leave(far->arrival, false);

  ASSERT_TRUE(q.try_push(queued(6, false, 200'000, 50)));  // a new robot's first scan: 1 ms predicted
  auto fresh = q.pop();
  ASSERT_TRUE(fresh);
  EXPECT_EQ(fresh->shared_refusal, "");
  q.charge(fresh->arrival, 900);  // it took far more: the budget (500) is spent
  q.leave(fresh->arrival, false);
  ASSERT_TRUE(q.try_push(queued(6, false, 200'000, 50)));
  ASSERT_TRUE(q.try_push(queued(0, true, 2'000'000, 50)));
  auto next = q.pop();
  ASSERT_TRUE(next);
  EXPECT_EQ(next->producer, 0u);  // the robot's, though it arrived after
  q.charge(next->arrival, 10);
  q.leave(next->arrival, true);
  EXPECT_GT(q.shared_deferrals(), 0u);
}

// Alone a scan delays no one: a producer without history whose scans nobody else waits beside
// is neither refused nor held back (a daemon serving one new robot is not throttled), and
// without a robot with history the budget per second does not hold the shared class back.
TEST(SharedClassBudget, InTheQueueAloneNoBound) {
  ScanQueue q(1 << 20, 8 << 20, true, kSharedClassShare, bounds());
  run_whole(q, queued(5, false, 400'000, 4000), 900);
  ASSERT_TRUE(q.try_push(queued(5, false, 400'000, 4000)));
  auto again = q.pop();
  ASSERT_TRUE(again);
  EXPECT_FALSE(again->others_stream);
  EXPECT_EQ(again->shared_refusal, "");
  q.charge(again->arrival, 900);
  q.leave(again->arrival, true);
  ASSERT_TRUE(q.try_push(queued(6, false, 200'000, 50)));  // another new robot: served though 1800 ms were used
  auto other = q.pop();
  ASSERT_TRUE(other);
  EXPECT_EQ(other->producer, 6u);
  EXPECT_EQ(q.shared_deferrals(), 0u);
}

}  // namespace
}  // namespace ort::daemon
