// The server's state (STARTING, RUNNING, DEGRADED, STOPPING, ERROR) with its message, and the
// heartbeat that reports it on OCTOMAP_RT_STATUS: a status every period, and one at once when
// the state is set, from a thread of its own. Each status applies the state rule first: ERROR
// once the LCM loop failed; RUNNING becomes DEGRADED while DegradedTracker finds a cause (and
// back when none is left).
//
// Usage: construct with the sources of a status (its figures of now, the rule's signals for
// them, a note said after the message); set_state() from any thread; start() once the server
// runs; stop() after the last set_state(): it publishes the status that says it, then joins.
// stamp() fills a status' state, message and sequence number from any thread.
#pragma once

#include <cstdint>
#include <functional>
#include <mutex>
#include <string>

#include "core/log.h"
#include "core/threads/periodic_thread.h"
#include "daemon/status/degraded_causes.h"
#include "daemon/status/status_message.h"
#include "daemon/transport/lcm_loop.h"
#include "octomap_rt/server_status_t.hpp"
#include "protocol/channels.h"

namespace ort::daemon {

struct StatusSources {
  std::function<StatusInputs()> gather;                         // the figures of now
  std::function<DegradedSignals(const StatusInputs&)> signals;  // the state rule's inputs
  std::function<std::string()> note;                            // "": none
};

struct StatusReporterConfig {
  std::string channel = ort::protocol::kStatusChannel;
  double period_s = 1.0;
  std::string running_message;  // what a RUNNING status says when it is no longer DEGRADED
};

class StatusReporter {
 public:
  StatusReporter(StatusReporterConfig cfg, LcmLoop& loop, StatusSources sources, Log log);
  ~StatusReporter() { stop(); }
  StatusReporter(const StatusReporter&) = delete;
  StatusReporter& operator=(const StatusReporter&) = delete;

  // The state and its message; the thread publishes a status at once.
  void set_state(int8_t state, std::string message);
  // The state, message and sequence number a status gathered now says.
  void stamp(StatusInputs& in) const;

  void start();
  // Publishes the status of the state as it is now, then joins. Idempotent.
  void stop();

 private:
  void publish();
  void publish_or_log();  // the periodic task: a failed status is logged, the next one tried

  const StatusReporterConfig cfg_;
  LcmLoop& loop_;
  const StatusSources sources_;
  Log log_;

  mutable std::mutex mutex_;  // state, message, seq
  int8_t state_ = octomap_rt::server_status_t::STATE_STARTING;
  std::string message_;
  int64_t seq_ = 0;
  DegradedTracker degraded_;  // the thread's only
  PeriodicThread periodic_;   // last: stopped before the members its task uses go
};

}  // namespace ort::daemon
