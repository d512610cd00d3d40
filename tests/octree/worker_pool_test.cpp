// The octree stage's worker pool: every worker runs every job exactly once, the caller sees
// the workers' plain writes when run() returns, errors come back to the caller, and the pool
// works whether its threads catch the next job while spinning or must be woken from sleep.
// A shared job (run_shared) has all its chunks done once, by whichever threads joined, no
// thread runs it twice or after it returned, also between run() jobs.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "core/clock.h"
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

// A shared job of `chunks` chunks; counts each chunk's runs and each worker's bodies.
void run_chunks(WorkerPool& pool, std::vector<int>& chunk_runs, std::vector<int>& bodies,
                const std::atomic<bool>& returned, std::atomic<int>& late) {
  std::atomic<size_t> next{0};
  std::fill(bodies.begin(), bodies.end(), 0);
  pool.run_shared([&](unsigned w) {
    if (returned.load()) late.fetch_add(1);
    ++bodies[w];
    for (size_t k; (k = next.fetch_add(1)) < chunk_runs.size();) {
      ++chunk_runs[k];  // plain: one thread a chunk
      // A few microseconds of work a chunk, so that woken threads join the job.
      const auto until = SteadyClock::now() + std::chrono::microseconds(20);
      while (SteadyClock::now() < until) {}
    }
  });
}

TEST_P(WorkerPoolTest, SharedJobsDoEveryChunkOnceWhoeverJoins) {
  const PoolCase c = GetParam();
  WorkerPool pool(c.workers, c.spin);
  std::atomic<bool> returned{false};
  std::atomic<int> late{0};
  std::vector<int> bodies(c.workers);
  unsigned most_joined = 0;
  for (int job = 0; job < 300; ++job) {
    std::vector<int> chunk_runs(job % 7 == 0 ? 1 : 40, 0);
    returned = false;
    run_chunks(pool, chunk_runs, bodies, returned, late);
    returned = true;
    for (size_t k = 0; k < chunk_runs.size(); ++k) ASSERT_EQ(chunk_runs[k], 1) << "chunk " << k << ", job " << job;
    ASSERT_EQ(bodies[0], 1);
    unsigned joined = 0;
    for (unsigned w = 0; w < c.workers; ++w) {
      ASSERT_LE(bodies[w], 1) << "worker " << w << " ran job " << job << " twice";
      joined += static_cast<unsigned>(bodies[w]);
    }
    most_joined = std::max(most_joined, joined);
    if (job % 3 == 0) {  // a job every thread runs, between shared ones
      std::vector<int> runs(c.workers, 0);
      pool.run([&](unsigned w) { ++runs[w]; });
      for (unsigned w = 0; w < c.workers; ++w) ASSERT_EQ(runs[w], 1) << "worker " << w << ", job " << job;
    }
  }
  EXPECT_EQ(late.load(), 0) << "a body ran after run_shared returned";
  std::printf("at most %u of %u threads joined a shared job\n", most_joined, c.workers);
}

TEST_P(WorkerPoolTest, AnErrorInASharedJobReachesTheCallerAndThePoolGoesOn) {
  const PoolCase c = GetParam();
  WorkerPool pool(c.workers, c.spin);
  for (size_t bad = 0; bad < 8; ++bad) {
    std::atomic<size_t> next{0};
    EXPECT_THROW(pool.run_shared([&](unsigned) {
      for (size_t k; (k = next.fetch_add(1)) < 8;)
        if (k == bad) throw std::runtime_error("chunk failed");
    }),
                 std::runtime_error)
        << "chunk " << bad;
    std::atomic<int> chunks{0};
    std::atomic<size_t> again{0};
    pool.run_shared([&](unsigned) {
      while (again.fetch_add(1) < 8) chunks.fetch_add(1);
    });
    EXPECT_EQ(chunks.load(), 8);
  }
}

INSTANTIATE_TEST_SUITE_P(Pools, WorkerPoolTest,
                         ::testing::Values(PoolCase{1, false}, PoolCase{2, false}, PoolCase{2, true},
                                           PoolCase{5, false}, PoolCase{5, true}),
                         [](const ::testing::TestParamInfo<PoolCase>& i) {
                           return std::to_string(i.param.workers) + (i.param.spin ? "Spinning" : "Sleeping");
                         });

}  // namespace
}  // namespace ort
