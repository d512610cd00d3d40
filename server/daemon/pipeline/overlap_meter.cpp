#include "daemon/pipeline/overlap_meter.h"

#include "core/clock.h"

namespace ort::daemon {

void OverlapMeter::advance(SteadyClock::time_point now) {
  const double dt = std::chrono::duration<double>(now - last_).count();
  last_ = now;
  if (busy_[0]) t_.busy_s[0] += dt;
  if (busy_[1]) t_.busy_s[1] += dt;
  if (busy_[0] && busy_[1]) t_.both_s += dt;
}

double OverlapMeter::begin(int stage) {
  std::lock_guard lock(mutex_);
  advance(SteadyClock::now());
  busy_[stage] = true;
  return t_.both_s;
}

double OverlapMeter::end(int stage, double begin_token) {
  std::lock_guard lock(mutex_);
  advance(SteadyClock::now());
  busy_[stage] = false;
  return t_.both_s - begin_token;
}

OverlapTotals OverlapMeter::totals() {
  std::lock_guard lock(mutex_);
  advance(SteadyClock::now());
  return t_;
}

}  // namespace ort::daemon
