#include "daemon/pipeline/latency_window.h"

#include <algorithm>
#include <cmath>

namespace ort::daemon {

void LatencyWindow::add(double v) {
  if (samples_.size() < capacity_) {
    samples_.push_back(v);
  } else {
    samples_[next_] = v;
    next_ = (next_ + 1) % capacity_;
  }
}

double LatencyWindow::percentile(double q) const {
  if (samples_.empty()) return 0;
  std::vector<double> s = samples_;
  const size_t rank = static_cast<size_t>(std::ceil(q * static_cast<double>(s.size())));
  const size_t i = rank == 0 ? 0 : std::min(rank - 1, s.size() - 1);
  std::nth_element(s.begin(), s.begin() + static_cast<std::ptrdiff_t>(i), s.end());
  return s[i];
}

}  // namespace ort::daemon
