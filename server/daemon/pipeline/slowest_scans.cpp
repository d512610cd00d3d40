#include "daemon/pipeline/slowest_scans.h"

#include <algorithm>

namespace ort::daemon {

void SlowestScans::add(const AppliedTiming& t) {
  applied_++;
  if (!have_first_ || t.received < first_received_) {
    first_received_ = t.received;
    have_first_ = true;
  }
  if (kept_ == 0) return;
  if (slowest_.size() == kept_ && t.end_to_end_ms <= slowest_.back().timing.end_to_end_ms) return;
  SlowScan s;
  s.applied_index = applied_;
  s.timing = t;
  const auto at = std::upper_bound(slowest_.begin(), slowest_.end(), s.timing.end_to_end_ms,
                                   [](double e2e, const SlowScan& x) { return e2e > x.timing.end_to_end_ms; });
  slowest_.insert(at, std::move(s));
  if (slowest_.size() > kept_) slowest_.pop_back();
}

std::vector<SlowScan> SlowestScans::slowest() const {
  std::vector<SlowScan> out = slowest_;
  for (auto& s : out) s.received_s = std::chrono::duration<double>(s.timing.received - first_received_).count();
  return out;
}

}  // namespace ort::daemon
