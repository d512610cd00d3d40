// A thread that runs one task periodically until it is stopped: the wait between two runs
// ends at once on stop() (or on wake()), so a stop never waits out a period. The daemon's
// periodic loops (saves, status, upkeep, the viewer map, deltas, the grid) each own one.
//
// Usage: start(period_s, task, options) once (a second start, or one after stop(), does
// nothing); wake() from any thread to run the task now; stop() from any thread but the
// task's own: it wakes the wait, lets a run in progress finish (and, with run_on_stop, runs
// the task once more), then joins. Idempotent; the destructor stops. A task that loops on its
// own (a sweep in slices) waits between its steps with pause(), which returns false once a
// stop was asked for. Exceptions thrown by the task end the process (std::terminate): catch
// and log them in the task.
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

#include "core/clock.h"

namespace ort {

struct PeriodicOptions {
  bool run_first = false;    // run once at start, before the first wait
  bool run_on_stop = false;  // a last run after stop() (e.g. a final status, what is pending)
  // Periods counted from one start to the next (a slow run shortens the next wait, no
  // catch-up burst); false: a full period from the end of one run to the start of the next.
  bool fixed_rate = false;
};

class PeriodicThread {
 public:
  PeriodicThread() = default;
  ~PeriodicThread() { stop(); }
  PeriodicThread(const PeriodicThread&) = delete;
  PeriodicThread& operator=(const PeriodicThread&) = delete;

  void start(double period_s, std::function<void()> task, PeriodicOptions options = {});
  // Runs the task now (or right after the run in progress), then periods go on from there.
  void wake();
  void stop();
  // From the task: waits `d` unless a stop comes first. false: stop() was called.
  bool pause(SteadyClock::duration d);
  bool running() const { return thread_.joinable(); }

 private:
  void run(SteadyClock::duration period, PeriodicOptions options);

  std::function<void()> task_;
  std::mutex mutex_;  // stopping_, woken_
  std::condition_variable wake_;
  bool stopping_ = false, woken_ = false;
  std::thread thread_;
};

}  // namespace ort
