#include "daemon/status/degraded_causes.h"

#include <sstream>

namespace ort::daemon {

std::string DegradedTracker::causes(const DegradedSignals& s) {
  std::ostringstream why;
  if (!s.save_error.empty()) why << "save failing (" << s.save_error << "); ";
  if (s.stuck_stage_s > 0 && s.longest_busy_s > s.stuck_stage_s)
    why << "stage stuck (" << static_cast<int>(s.longest_busy_s) << " s on one scan); ";
  if (s.queue_bytes > s.queue_total_budget * 9 / 10 || (s.latency_bound_s > 0 && s.oldest_queued_s > s.latency_bound_s))
    why << "queue over its bound (" << (s.queue_bytes >> 20) << " MiB, oldest " << s.oldest_queued_s << " s); ";
  if (s.latency_bound_s > 0 && s.e2e_p99_ms > s.latency_bound_s * 1000.0)
    why << "latency over its bound (p99 " << s.e2e_p99_ms / 1000.0 << " s > " << s.latency_bound_s << " s); ";
  if (s.scans_dropped > last_dropped_) why << (s.scans_dropped - last_dropped_) << " scans dropped; ";
  if (s.scans_rejected > last_rejected_) why << (s.scans_rejected - last_rejected_) << " scans rejected; ";
  // The first known count is only a baseline: drops before the server started are not its own.
  if (last_kernel_drops_ >= 0 && s.kernel_drops > last_kernel_drops_)
    why << (s.kernel_drops - last_kernel_drops_)
        << " UDP datagrams dropped by the kernel on the server's socket (receive buffer full); ";
  last_dropped_ = s.scans_dropped;
  last_rejected_ = s.scans_rejected;
  last_kernel_drops_ = s.kernel_drops;
  return why.str();
}

}  // namespace ort::daemon
