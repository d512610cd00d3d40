// The last N samples of one latency, for p50/p99 in the status (a recent window, not since
// start, so the status shows the server as it is now).
#pragma once

#include <cstddef>
#include <vector>

namespace ort::daemon {

class LatencyWindow {
 public:
  explicit LatencyWindow(size_t capacity = 512) : capacity_(capacity) { samples_.reserve(capacity); }
  void add(double v);
  // Nearest-rank percentile, q in [0, 1]; 0 when empty.
  double percentile(double q) const;
  size_t size() const { return samples_.size(); }

 private:
  size_t capacity_;
  size_t next_ = 0;
  std::vector<double> samples_;
};

}  // namespace ort::daemon
