#include "octree/worker_pool.h"

#include <chrono>

#include "core/clock.h"
#include "core/thread_priority.h"

namespace ort {
namespace {

// How long a thread spins for a change before it sleeps: longer than the serial steps
// between one scan's jobs (tens of microseconds), short against a scan.
constexpr std::chrono::microseconds kSpin{100};

inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

// Returns once `value` no longer holds `old` (acquire); spins first when `spin`.
template <class T>
void wait_for_change(const std::atomic<T>& value, T old, bool spin) {
  const auto until = SteadyClock::now() + kSpin;
  for (unsigned i = 1; spin; ++i) {
    if (value.load(std::memory_order_acquire) != old) return;
    cpu_relax();
    if (i % 64 == 0 && SteadyClock::now() >= until) break;
  }
  while (value.load(std::memory_order_acquire) == old) value.wait(old, std::memory_order_acquire);
}

}  // namespace

unsigned resolve_thread_count(unsigned requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? hw : 1;
}

WorkerPool::WorkerPool(unsigned workers, std::optional<bool> spin, int helper_nice)
    : spin_(spin.value_or(workers < std::thread::hardware_concurrency())) {
  for (unsigned w = 1; w < workers; ++w)
    threads_.emplace_back([this, w, helper_nice] {
      lower_this_thread_priority(helper_nice);
      thread_main(w);
    });
}

WorkerPool::~WorkerPool() {
  stopping_.store(true, std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_release);
  generation_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void WorkerPool::run(const std::function<void(unsigned)>& body) {
  error_ = nullptr;
  job_ = &body;
  const uint32_t threads = static_cast<uint32_t>(threads_.size());
  running_.store(threads, std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_release);
  if (threads > 0) generation_.notify_all();
  std::exception_ptr own_error;
  try {
    body(0);
  } catch (...) {
    own_error = std::current_exception();
  }
  for (uint32_t left; (left = running_.load(std::memory_order_acquire)) != 0;) wait_for_change(running_, left, spin_);
  job_ = nullptr;
  if (own_error) std::rethrow_exception(own_error);
  if (error_) std::rethrow_exception(error_);
}

void WorkerPool::run_shared(const std::function<void(unsigned)>& body) {
  error_ = nullptr;
  job_ = &body;
  const uint32_t gen = generation_.load(std::memory_order_relaxed) + 1;
  // The job's state before its generation (release): a thread that sees the generation sees it.
  job_state_.store(uint64_t{gen} << 32, std::memory_order_relaxed);
  generation_.store(gen, std::memory_order_release);
  if (!threads_.empty()) generation_.notify_all();
  std::exception_ptr own_error;
  try {
    body(0);
  } catch (...) {
    own_error = std::current_exception();
  }
  // Closed: no thread joins from now on; wait for those inside.
  for (uint64_t s = job_state_.fetch_or(kClosed, std::memory_order_acq_rel) | kClosed; (s & kInside) != 0;
       s = job_state_.load(std::memory_order_acquire))
    wait_for_change(job_state_, s, spin_);
  job_ = nullptr;
  if (own_error) std::rethrow_exception(own_error);
  if (error_) std::rethrow_exception(error_);
}

void WorkerPool::run_body(unsigned worker) {
  try {
    (*job_)(worker);
  } catch (...) {
    std::lock_guard lock(error_mutex_);
    if (!error_) error_ = std::current_exception();
  }
}

void WorkerPool::join_shared(unsigned worker, uint32_t gen) {
  uint64_t s = job_state_.load(std::memory_order_acquire);
  do {
    if ((s >> 32) != gen || (s & kClosed)) return;  // over (or a later job's): not this thread's
  } while (!job_state_.compare_exchange_weak(s, s + 1, std::memory_order_acquire, std::memory_order_acquire));
  run_body(worker);
  // acq_rel: the caller's acquire of "closed, none inside" sees this thread's writes.
  const uint64_t left = job_state_.fetch_sub(1, std::memory_order_acq_rel) - 1;
  if ((left & kClosed) && (left & kInside) == 0) job_state_.notify_one();
}

void WorkerPool::thread_main(unsigned worker) {
  uint32_t seen = 0;  // the generation this thread ran last (0: none yet)
  for (;;) {
    wait_for_change(generation_, seen, spin_);
    seen = generation_.load(std::memory_order_acquire);
    if (stopping_.load(std::memory_order_relaxed)) return;
    // A run() job waits for every thread, so a thread behind by a job can only be behind a
    // run_shared() one: its state then carries this generation, closed, or a later one (the
    // caller has already started the next shared job: this one is over, and its body must not
    // be run as a run() job's). Only a state older than `seen` means a run() job.
    const uint32_t state_generation = static_cast<uint32_t>(job_state_.load(std::memory_order_acquire) >> 32);
    if (state_generation == seen) {
      join_shared(worker, seen);
      continue;
    }
    if (static_cast<int32_t>(state_generation - seen) > 0) continue;  // modulo 2^32, as generations count
    run_body(worker);
    // acq_rel: the caller's acquire of 0 sees this thread's writes (and the error).
    if (running_.fetch_sub(1, std::memory_order_acq_rel) == 1) running_.notify_one();
  }
}

}  // namespace ort
