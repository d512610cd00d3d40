#include "daemon/status/status_reporter.h"

namespace ort::daemon {

using Status = octomap_rt::server_status_t;

StatusReporter::StatusReporter(StatusReporterConfig cfg, LcmLoop& loop, StatusSources sources, Log log)
    : cfg_(std::move(cfg)), loop_(loop), sources_(std::move(sources)), log_(std::move(log)) {}

void StatusReporter::set_state(int8_t state, std::string message) {
  {
    std::lock_guard lock(mutex_);
    state_ = state;
    message_ = std::move(message);
  }
  periodic_.wake();
}

void StatusReporter::stamp(StatusInputs& in) const {
  std::lock_guard lock(mutex_);
  in.state = state_;
  in.message = message_;
  in.seq = seq_;
}

void StatusReporter::start() {
  PeriodicOptions o;
  o.run_on_stop = true;  // the status that says how the server stopped
  periodic_.start(
      cfg_.period_s, [this] { publish_or_log(); }, o);
}

void StatusReporter::stop() { periodic_.stop(); }

void StatusReporter::publish_or_log() {
  try {
    publish();
  } catch (const std::exception& e) {
    log_.error(text("status failed: ", e.what()));
  }
}

void StatusReporter::publish() {
  StatusInputs in = sources_.gather();
  const std::string why = degraded_.causes(sources_.signals(in));
  {
    std::lock_guard lock(mutex_);
    if (loop_.failed()) {
      state_ = Status::STATE_ERROR;
      message_ = "LCM intake failed; no scans are received";
    } else if (state_ == Status::STATE_RUNNING && !why.empty()) {
      state_ = Status::STATE_DEGRADED;
      message_ = "degraded: " + why;
    } else if (state_ == Status::STATE_DEGRADED) {
      if (why.empty()) {
        state_ = Status::STATE_RUNNING;
        message_ = cfg_.running_message;
      } else {
        message_ = "degraded: " + why;
      }
    }
    in.state = state_;
    in.message = message_;
    in.seq = seq_++;
  }
  if (const std::string note = sources_.note ? sources_.note() : ""; !note.empty()) in.message += "; " + note;
  loop_.publish(cfg_.channel, make_status(in));
}

}  // namespace ort::daemon
