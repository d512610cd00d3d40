// The few scans with the longest end-to-end time over the whole run, each with where its time
// went (waits, stage 1's parts, stage 2's parts) and when it came: the run summary lists them,
// so a p99 over a run says which scans made it (the first ones of a fresh daemon, a burst of
// three, a slow octree update) and which part of them was slow.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/clock.h"
#include "daemon/pipeline/applied_timing.h"

namespace ort::daemon {

struct SlowScan {
  int64_t applied_index = 0;  // 1 = the first scan the daemon applied
  double received_s = 0;      // receipt, seconds after the earliest receipt of an applied scan
  AppliedTiming timing;
};

class SlowestScans {
 public:
  explicit SlowestScans(size_t kept = 5) : kept_(kept) {}
  // Every applied scan, in applied order.
  void add(const AppliedTiming& t);
  // The kept scans, slowest first (end to end), each received_s from the earliest receipt of
  // all applied so far: across producers scans may be applied out of arrival order (round
  // robin in the shared class), so the first applied need not have come first.
  std::vector<SlowScan> slowest() const;

 private:
  size_t kept_;
  int64_t applied_ = 0;
  bool have_first_ = false;
  SteadyClock::time_point first_received_;
  std::vector<SlowScan> slowest_;
};

}  // namespace ort::daemon
