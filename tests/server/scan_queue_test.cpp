// The queue's share of the stages (intake/scan_queue.h), on its own: the class that used less
// of the stages' time goes first, producers without history share one turn and one byte
// budget, a class ahead has one scan in the stages while one behind it streams, a scan
// passed over is marked, edits keep their place, and fair = false is one FIFO.
#include "daemon/intake/scan_queue.h"

#include <chrono>
#include <future>
#include <vector>

#include <gtest/gtest.h>

namespace ort::daemon {
namespace {

QueuedScan scan_of(size_t producer, bool established, size_t bytes = 100) {
  QueuedScan s;
  s.producer = producer;
  s.established = established;
  s.bytes = bytes;
  s.received = SteadyClock::now();
  return s;
}

TEST(ScanQueue, TheClassThatUsedLessOfTheStagesGoesFirst) {
  ScanQueue q(1 << 20, 8 << 20);
  for (size_t fresh = 1; fresh <= 3; ++fresh) ASSERT_TRUE(q.try_push(scan_of(fresh, false)));
  ASSERT_TRUE(q.try_push(scan_of(0, true)));
  auto first = q.pop();  // a tie at nothing used: the oldest
  ASSERT_TRUE(first);
  EXPECT_EQ(first->producer, 1u);
  EXPECT_EQ(first->share_class, kNewProducersClass);
  q.charge(first->share_class, 1000);  // a far scan's walk and apply
  q.leave(*first);
  auto robot = q.pop();
  ASSERT_TRUE(robot);
  EXPECT_EQ(robot->producer, 0u);
  EXPECT_EQ(robot->share_class, 0u);
  EXPECT_FALSE(robot->passed_over);
  q.charge(robot->share_class, 10);
  q.leave(*robot);
  // The robot's next scan goes before the two fresh ids' older ones; they are marked passed over.
  ASSERT_TRUE(q.try_push(scan_of(0, true)));
  EXPECT_EQ(q.pop()->producer, 0u);
  q.leave(0);
  auto next = q.pop();
  ASSERT_TRUE(next);
  EXPECT_EQ(next->producer, 2u);
  EXPECT_TRUE(next->passed_over);
}

// A robot's first scans wait in the shared class; once it has history, they and its new ones
// are served in its own class, in its order, however long a flood keeps the shared class's
// backlog (they used to stay there until no scan of the robot waited in it: never, under a flood).
TEST(ScanQueue, ARobotThatEarnsItsHistoryTakesItsWaitingScansOutOfTheSharedClass) {
  ScanQueue q(1 << 20, 8 << 20);
  ASSERT_TRUE(q.try_push(scan_of(1, false)));
  ASSERT_TRUE(q.try_push(scan_of(2, false)));
  ASSERT_TRUE(q.try_push(scan_of(0, false, 300)));  // the robot, before its history
  ASSERT_TRUE(q.try_push(scan_of(3, false)));
  auto far = q.pop();
  ASSERT_EQ(far->producer, 1u);
  q.charge(far->share_class, 1000);
  q.leave(*far);
  ASSERT_TRUE(q.try_push(scan_of(0, true, 300)));  // now with history
  EXPECT_EQ(q.producer_bytes(0), 600u);
  std::vector<size_t> producers;
  uint64_t last_robot_arrival = 0;
  while (q.depth() > 0) {
    auto s = q.pop();
    ASSERT_TRUE(s);
    producers.push_back(s->producer);
    if (s->producer == 0) {
      EXPECT_EQ(s->share_class, 0u);
      EXPECT_GT(s->arrival, last_robot_arrival);  // its order kept
      last_robot_arrival = s->arrival;
    }
    q.charge(s->share_class, 10);
    q.leave(*s);
  }
  EXPECT_EQ(producers, (std::vector<size_t>{0, 0, 2, 3}));
  EXPECT_EQ(q.producer_bytes(0), 0u);
  // The shared class's byte budget is free of the robot's scans again: fresh ids fill it alone.
  ScanQueue small(700, 1 << 20);
  ASSERT_TRUE(small.try_push(scan_of(0, false, 300)));
  ASSERT_TRUE(small.try_push(scan_of(0, true, 300)));
  EXPECT_TRUE(small.try_push(scan_of(1, false, 600)));
}

TEST(ScanQueue, ProducersWithoutHistoryShareOneByteBudget) {
  ScanQueue q(1000, 1 << 20);
  EXPECT_TRUE(q.try_push(scan_of(1, false, 400)));
  EXPECT_TRUE(q.try_push(scan_of(2, false, 400)));
  EXPECT_FALSE(q.try_push(scan_of(3, false, 400)));  // a third fresh id: the class's budget is full
  EXPECT_TRUE(q.try_push(scan_of(4, true, 400)));    // a robot with history has its own
  ScanQueue fifo(1000, 1 << 20, false);
  for (size_t p = 1; p <= 3; ++p) EXPECT_TRUE(fifo.try_push(scan_of(p, false, 400)));
}

TEST(ScanQueue, AClassAheadHasOneScanInTheStagesWhileOneBehindItStreams) {
  ScanQueue q(1 << 20, 8 << 20);
  ASSERT_TRUE(q.try_push(scan_of(0, true)));
  auto robot = q.pop();
  q.leave(*robot);  // the robot streams: served a moment ago
  ASSERT_TRUE(q.try_push(scan_of(1, false)));
  ASSERT_TRUE(q.try_push(scan_of(2, false)));
  auto far = q.pop();
  ASSERT_EQ(far->producer, 1u);
  q.charge(far->share_class, 1000);  // in the stages, ahead of the robot
  auto waiting = std::async(std::launch::async, [&] { return q.pop(); });
  EXPECT_EQ(waiting.wait_for(std::chrono::milliseconds(150)), std::future_status::timeout);
  q.leave(*far);
  ASSERT_EQ(waiting.wait_for(std::chrono::seconds(5)), std::future_status::ready);
  EXPECT_EQ(waiting.get()->producer, 2u);
}

TEST(ScanQueue, AnEditLeavesAfterTheScansBeforeItAndBeforeThoseAfter) {
  ScanQueue q(1 << 20, 8 << 20);
  ASSERT_TRUE(q.try_push(scan_of(1, false)));
  ASSERT_TRUE(q.push_edit(nullptr));
  ASSERT_TRUE(q.try_push(scan_of(0, true)));
  EXPECT_EQ(q.pop()->producer, 1u);
  q.leave(kNewProducersClass);
  auto edit = q.pop();
  ASSERT_TRUE(edit);
  EXPECT_GT(edit->arrival, 0u);
  EXPECT_EQ(edit->producer, 0u);
  EXPECT_EQ(q.pop()->share_class, 0u);
  EXPECT_EQ(q.depth(), 0u);
}

TEST(ScanQueue, WithoutTheShareItIsOneFifo) {
  ScanQueue q(1 << 20, 8 << 20, false);
  ASSERT_TRUE(q.try_push(scan_of(1, false)));
  ASSERT_TRUE(q.try_push(scan_of(0, true)));
  ASSERT_TRUE(q.try_push(scan_of(1, false)));
  auto a = q.pop();
  q.charge(a->share_class, 1000);
  q.leave(*a);
  EXPECT_EQ(q.pop()->producer, 0u);
  EXPECT_EQ(q.pop()->producer, 1u);
  EXPECT_NE(q.policy().find("one FIFO"), std::string::npos);
}

}  // namespace
}  // namespace ort::daemon
