// A fixed set of threads that run one job at a time, all of them together: the octree stage
// hands each scan's subtrees to them. The threads are started once and wait between scans,
// because starting 16 threads per scan costs about as much as a small scan's update.
//
// One scan's update is five jobs back to back (four bucketing passes, then the subtrees)
// with short serial steps between them, each job short on 16 threads. So a thread that
// finished a job first spins on the job counter for a short while (the next job of the same
// scan usually comes within it) and only then sleeps on a futex (std::atomic::wait); run()
// wakes every sleeper with one notify and waits for the last one the same way. Spinning
// only where the pool leaves a hardware thread free (the octree stage beside a device stage
// 1 takes 15 of 16): where the workers take every core (the daemon, 2-core machines) a
// spinning thread would take the core from the thread it waits for. A mutex and
// condition variable here cost tens of microseconds per job on 16 threads: every woken thread
// re-took the mutex one after the other, and so did every finishing one.
//
// run_shared() is for jobs whose work the bodies share out themselves (chunks from an atomic
// counter): a thread joins such a job only while the caller is still in its own part of it,
// and the caller waits only for the threads that joined. A worker preempted or asleep when
// the job came (another process on its core, a slow wake-up) then holds up nobody: the others
// take its chunks, and it skips the job when it runs again. With run(), every join waits for
// the slowest thread to start.
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

namespace ort {

class WorkerPool {
 public:
  // `workers` >= 1; worker 0 is the thread that calls run(), the others are started here.
  // `spin`: whether waiting threads spin first; unset: where workers < hardware threads.
  // `helper_nice`: how much the started threads lower their priority below the caller's
  // (core/thread_priority.h; 19: the lowest). Such helpers take only cores nothing else
  // wants: run_shared jobs go on without the ones that do not get a core (the caller alone
  // does what is left).
  explicit WorkerPool(unsigned workers, std::optional<bool> spin = std::nullopt, int helper_nice = 0);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  unsigned size() const { return static_cast<unsigned>(threads_.size()) + 1; }

  // Runs body(w) for every worker w in [0, size()) at once and returns when all have
  // returned; everything the bodies wrote is visible to the caller then. Rethrows the first
  // exception a body threw. Not to be called from two threads at once.
  void run(const std::function<void(unsigned worker)>& body);

  // Runs body(0) on the caller and body(w) on each worker w that joins before body(0)
  // returns (none, some or all of them; each at most once); returns when every body that
  // started has returned, with their writes visible. The bodies must share the work out
  // among themselves, so that body(0) alone does whatever is left. Rethrows the first
  // exception a body threw.
  void run_shared(const std::function<void(unsigned worker)>& body);

 private:
  void thread_main(unsigned worker);
  // A run_shared job: joins generation `gen` unless it is closed or gone; runs it if joined.
  void join_shared(unsigned worker, uint32_t gen);
  void run_body(unsigned worker);

  // run_shared's job: generation << 32 | kClosed | threads inside the job.
  static constexpr uint64_t kClosed = uint64_t{1} << 31;
  static constexpr uint64_t kInside = kClosed - 1;
  std::atomic<uint64_t> job_state_{0};

  // Bumped (release) once per job and once to stop: a thread runs each value once.
  std::atomic<uint32_t> generation_{0};
  std::atomic<uint32_t> running_{0};  // threads still in the current job
  std::atomic<bool> stopping_{false};
  const bool spin_;
  const std::function<void(unsigned)>* job_ = nullptr;  // written before generation_ is bumped
  std::mutex error_mutex_;
  std::exception_ptr error_;
  std::vector<std::thread> threads_;
};

// 0 means all hardware threads.
unsigned resolve_thread_count(unsigned requested);

}  // namespace ort
