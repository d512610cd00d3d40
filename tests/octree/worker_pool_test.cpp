// The octree stage's worker pool: every worker runs every job exactly once, the caller sees
// the workers' plain writes when run() returns, errors come back to the caller, and the pool
// works whether its threads catch the next job while spinning or must be woken from sleep.
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "octree/worker_pool.h"

namespace ort {
namespace {

struct PoolCase {
  unsigned workers;
  bool spin;
};

class WorkerPoolTest : public ::testing::TestWithParam<PoolCase> {};

TEST_P(WorkerPoolTest, EveryWorkerRunsEveryJobOnceAndItsWritesAreSeen) {
  const PoolCase c = GetParam();
  WorkerPool pool(c.workers, c.spin);
  ASSERT_EQ(pool.size(), c.workers);
  std::vector<int> runs(c.workers, 0);  // plain ints: each worker writes only its own
  for (int job = 0; job < 3000; ++job) {
    std::atomic<unsigned> entered{0};
    pool.run([&](unsigned w) {
      ASSERT_LT(w, c.workers);
      ++runs[w];
      entered.fetch_add(1, std::memory_order_relaxed);
    });
    ASSERT_EQ(entered.load(), c.workers) << "job " << job;
    for (unsigned w = 0; w < c.workers; ++w) ASSERT_EQ(runs[w], job + 1) << "worker " << w << ", job " << job;
  }
}

TEST_P(WorkerPoolTest, SleepingThreadsAreWokenForTheNextJob) {
  const PoolCase c = GetParam();
  WorkerPool pool(c.workers, c.spin);
  std::vector<int> runs(c.workers, 0);
  for (int job = 0; job < 5; ++job) {
    // Longer than any spin: the threads are asleep when the job comes.
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    pool.run([&](unsigned w) { ++runs[w]; });
    for (unsigned w = 0; w < c.workers; ++w) ASSERT_EQ(runs[w], job + 1);
  }
}

TEST_P(WorkerPoolTest, AnErrorOfAnyWorkerReachesTheCallerAndThePoolGoesOn) {
  const PoolCase c = GetParam();
  WorkerPool pool(c.workers, c.spin);
  for (unsigned thrower = 0; thrower < c.workers; ++thrower) {
    std::atomic<unsigned> finished{0};
    EXPECT_THROW(pool.run([&](unsigned w) {
      if (w == thrower) throw std::runtime_error("worker failed");
      finished.fetch_add(1);
    }),
                 std::runtime_error)
        << "thrower " << thrower;
    EXPECT_EQ(finished.load(), c.workers - 1) << "run() returned before the other workers were done";
    std::atomic<unsigned> after{0};
    pool.run([&](unsigned) { after.fetch_add(1); });
    EXPECT_EQ(after.load(), c.workers);
  }
}

TEST_P(WorkerPoolTest, IsDestroyedWhileItsThreadsSleepOrSpin) {
  const PoolCase c = GetParam();
  for (int wait_ms : {0, 20}) {
    WorkerPool pool(c.workers, c.spin);
    pool.run([](unsigned) {});
    std::this_thread::sleep_for(std::chrono::milliseconds(wait_ms));
  }  // the destructor joins: a hang here fails the test by its timeout
}

INSTANTIATE_TEST_SUITE_P(Pools, WorkerPoolTest,
                         ::testing::Values(PoolCase{1, false}, PoolCase{2, false}, PoolCase{2, true}, PoolCase{5, false},
                                           PoolCase{5, true}),
                         [](const ::testing::TestParamInfo<PoolCase>& i) {
                           return std::to_string(i.param.workers) + (i.param.spin ? "Spinning" : "Sleeping");
                         });

}  // namespace
}  // namespace ort
