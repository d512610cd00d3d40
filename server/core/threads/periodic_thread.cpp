#include "core/threads/periodic_thread.h"

#include <algorithm>

namespace ort {

void PeriodicThread::start(double period_s, std::function<void()> task, PeriodicOptions options) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_ || thread_.joinable()) return;
  }
  task_ = std::move(task);
  const auto period = std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(period_s));
  thread_ = std::thread([this, period, options] { run(period, options); });
}

void PeriodicThread::wake() {
  {
    std::lock_guard lock(mutex_);
    woken_ = true;
  }
  wake_.notify_all();
}

void PeriodicThread::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool PeriodicThread::pause(SteadyClock::duration d) {
  std::unique_lock lock(mutex_);
  return !wake_.wait_for(lock, d, [this] { return stopping_; });
}

void PeriodicThread::run(SteadyClock::duration period, PeriodicOptions options) {
  // Behind (a slow run) at a fixed rate: the next run at once, never a burst to catch up.
  auto next_after = [&](SteadyClock::time_point started) {
    return options.fixed_rate ? std::max(started + period, SteadyClock::now()) : SteadyClock::now() + period;
  };
  auto next = SteadyClock::now() + period;
  if (options.run_first) {
    const auto started = SteadyClock::now();
    task_();
    next = next_after(started);
  }
  for (;;) {
    {
      std::unique_lock lock(mutex_);
      wake_.wait_until(lock, next, [this] { return stopping_ || woken_; });
      woken_ = false;
      if (stopping_) {
        lock.unlock();
        if (options.run_on_stop) task_();
        return;
      }
    }
    const auto started = SteadyClock::now();
    task_();
    next = next_after(started);
  }
}

}  // namespace ort
