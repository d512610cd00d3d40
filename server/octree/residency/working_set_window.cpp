#include "octree/residency/working_set_window.h"

#include <algorithm>

namespace ort {

WorkingSetWindow::WorkingSetWindow(double fixed_seconds, Clock clock)
    : fixed_s_(fixed_seconds > 0 ? fixed_seconds : 0),
      clock_(std::move(clock)),
      seconds_(fixed_s_ > 0 ? fixed_s_ : kFirstSeconds) {}

void WorkingSetWindow::scan(std::string_view source) {
  if (fixed_s_ > 0) return;  // the rate decides nothing
  const TimePoint at = now();
  auto it = sources_.find(std::string(source));
  if (it == sources_.end()) {
    if (sources_.size() >= kMaxSources) drop_oldest_source();
    sources_.emplace(std::string(source), Source{at, 0, false});
    return;  // one scan is no rate yet: T is unchanged
  }
  Source& s = it->second;
  const double interval = std::chrono::duration<double>(at - s.last).count();
  s.last = at;
  if (interval > kPauseSeconds || interval < 0) return;  // a pause: the mean is kept
  s.mean_s = s.has_mean ? (1 - kMeanWeight) * s.mean_s + kMeanWeight * interval : interval;
  s.has_mean = true;
  recompute();
}

void WorkingSetWindow::drop_oldest_source() {
  auto oldest = sources_.begin();
  for (auto it = sources_.begin(); it != sources_.end(); ++it)
    if (it->second.last < oldest->second.last) oldest = it;
  sources_.erase(oldest);
  recompute();
}

void WorkingSetWindow::recompute() {
  bool any = false;
  double longest = 0;
  for (const auto& [name, s] : sources_) {
    if (!s.has_mean) continue;
    any = true;
    longest = std::max(longest, s.mean_s);
  }
  seconds_ = any ? std::clamp(kRateFactor * longest, kMinSeconds, kMaxSeconds) : kFirstSeconds;
}

WorkingSetWindow::TimePoint WorkingSetWindow::idle_before() const {
  return now() - std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(seconds_));
}

WorkingSetWindow::TimePoint WorkingSetWindow::last_touch(RegionId id) const {
  const auto it = touched_.find(id);
  return it == touched_.end() ? TimePoint::min() : it->second;
}

}  // namespace ort
