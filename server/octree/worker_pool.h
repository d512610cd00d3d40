// A fixed set of threads that run one job at a time, all of them together: the octree stage
// hands each scan's subtrees to them. The threads are started once and wait between scans,
// because starting 16 threads per scan costs about as much as a small scan's update.
#pragma once

#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace ort {

class WorkerPool {
 public:
  // `workers` >= 1; worker 0 is the thread that calls run(), the others are started here.
  explicit WorkerPool(unsigned workers);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  unsigned size() const { return static_cast<unsigned>(threads_.size()) + 1; }

  // Runs body(w) for every worker w in [0, size()) at once and returns when all have
  // returned; everything the bodies wrote is visible to the caller then. Rethrows the first
  // exception a body threw. Not to be called from two threads at once.
  void run(const std::function<void(unsigned worker)>& body);

 private:
  void thread_main(unsigned worker);

  std::mutex mutex_;
  std::condition_variable job_ready_, job_done_;
  const std::function<void(unsigned)>* job_ = nullptr;
  unsigned long long generation_ = 0;  // counts jobs; a thread runs each generation once
  unsigned running_ = 0;               // threads still in the current job
  bool stopping_ = false;
  std::exception_ptr error_;
  std::vector<std::thread> threads_;
};

// 0 means all hardware threads.
unsigned resolve_thread_count(unsigned requested);

}  // namespace ort
