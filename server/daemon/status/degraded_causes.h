// Why the server is DEGRADED now: the rule behind the status' state and message.
//
// Two kinds of trouble count. Trouble in the last status period (scans dropped or rejected,
// datagrams the kernel dropped on the server's socket) is seen as a counter that grew since
// the previous call; trouble that lasts (a failing save, a stage stuck on one scan, a queue
// or the latency over its bound) is seen in the current figures. A tracker holds the counters
// of the previous call, so call causes() once per status period, from one thread.
#pragma once

#include <cstdint>
#include <string>

namespace ort::daemon {

// The figures the rule reads, gathered by the server for one status period.
struct DegradedSignals {
  std::string save_error;     // "" unless the latest periodic save failed
  double longest_busy_s = 0;  // the longest a stage has been busy on its current scan
  double stuck_stage_s = 0;   // <= 0: never called stuck
  uint64_t queue_bytes = 0, queue_total_budget = 0;
  double oldest_queued_s = 0;                     // age of the oldest queued scan
  double latency_bound_s = 0;                     // <= 0: no bound
  double e2e_p99_ms = 0;                          // end-to-end p99 over the latency window
  int64_t scans_dropped = 0, scans_rejected = 0;  // totals over all producers
  int64_t kernel_drops = -1;                      // datagrams dropped on the server's socket; < 0: unknown
};

class DegradedTracker {
 public:
  // "" when nothing is wrong, else the causes, each ending in "; ".
  std::string causes(const DegradedSignals& s);

 private:
  int64_t last_dropped_ = 0, last_rejected_ = 0, last_kernel_drops_ = -1;
};

}  // namespace ort::daemon
