#include "daemon/status/status_reporter.h"

#include <chrono>

namespace ort::daemon {

using Status = octomap_rt::server_status_t;

StatusReporter::StatusReporter(StatusReporterConfig cfg, LcmLoop& loop, StatusSources sources, Log log)
    : cfg_(std::move(cfg)), loop_(loop), sources_(std::move(sources)), log_(std::move(log)) {}

void StatusReporter::set_state(int8_t state, std::string message) {
  {
    std::lock_guard lock(mutex_);
    state_ = state;
    message_ = std::move(message);
    changed_ = true;
  }
  wake_.notify_all();
}

void StatusReporter::stamp(StatusInputs& in) const {
  std::lock_guard lock(mutex_);
  in.state = state_;
  in.message = message_;
  in.seq = seq_;
}

void StatusReporter::start() {
  if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
}

void StatusReporter::stop() {
  {
    std::lock_guard lock(mutex_);
    exit_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void StatusReporter::run() {
  const auto period = std::chrono::duration<double>(cfg_.period_s);
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait_for(lock, period, [&] { return changed_ || exit_; });
    const bool exit = exit_;
    changed_ = false;
    lock.unlock();
    try {
      publish();
    } catch (const std::exception& e) {
      log_.error(text("status failed: ", e.what()));
    }
    lock.lock();
    if (exit) return;
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
