// Evidence that the pipeline overlaps: busy time of stage 1 (GPU shoot) and stage 2 (CPU
// octree), and the time both were busy at once. Both stages never work on the same scan at
// once, so any time both are busy is stage 1 shooting a later scan while stage 2 updates an
// earlier one.
#pragma once

#include <chrono>
#include <mutex>

#include "core/clock.h"

namespace ort::daemon {

struct OverlapTotals {
  double busy_s[2] = {0, 0};  // [0]: stage 1, [1]: stage 2
  double both_s = 0;
};

class OverlapMeter {
 public:
  // stage: 0 = stage 1, 1 = stage 2. begin() returns the both-busy total so far; end()
  // returns how much both-busy time accrued since `begin_token` (> 0: this stage's work
  // overlapped the other stage's).
  double begin(int stage);
  double end(int stage, double begin_token);
  OverlapTotals totals();

 private:
  void advance(SteadyClock::time_point now);
  std::mutex mutex_;
  bool busy_[2] = {false, false};
  SteadyClock::time_point last_ = SteadyClock::now();
  OverlapTotals t_;
};

}  // namespace ort::daemon
