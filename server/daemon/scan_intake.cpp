#include "daemon/scan_intake.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>
#include <stdexcept>

namespace ort::daemon {

ScanIntake::ScanIntake(lcm::LCM& lc, std::string channel_regex, const ScanLimits& limits,
                       ProducerRegistry& producers, ScanQueue& queue, int lcm_queue_capacity)
    : lc_(lc), regex_(std::move(channel_regex)), limits_(limits), producers_(producers), queue_(queue),
      lcm_queue_capacity_(lcm_queue_capacity) {
  wake_fd_ = ::eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (wake_fd_ < 0) throw std::runtime_error(std::string("eventfd: ") + std::strerror(errno));
}

ScanIntake::~ScanIntake() {
  stop();
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

void ScanIntake::start() {
  sub_ = lc_.subscribe(regex_, &ScanIntake::on_message, this);
  if (!sub_) throw std::runtime_error("LCM: cannot subscribe to '" + regex_ + "'");
  // LCM's own queue drops silently when full (lcm-proj/lcm#345); our handler is quick, so a
  // moderate capacity suffices and bounds LCM's memory.
  sub_->setQueueCapacity(lcm_queue_capacity_);
  thread_ = std::thread([this] { run(); });
}

void ScanIntake::stop() {
  if (thread_.joinable()) {
    const uint64_t one = 1;
    if (::write(wake_fd_, &one, sizeof one) < 0) std::cerr << "octomap-rt-server: eventfd write failed\n";
    thread_.join();
  }
  if (sub_) {
    lc_.unsubscribe(sub_);
    sub_ = nullptr;
  }
}

void ScanIntake::run() {
  pollfd fds[2] = {{lc_.getFileno(), POLLIN, 0}, {wake_fd_, POLLIN, 0}};
  for (;;) {
    const int n = ::poll(fds, 2, -1);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      std::cerr << "octomap-rt-server: poll: " << std::strerror(errno) << "\n";
      failed_ = true;
      return;
    }
    if (fds[1].revents) return;
    if (fds[0].revents) {
      int r;
      while ((r = lc_.handleTimeout(0)) > 0) {
      }
      if (r < 0) {
        std::cerr << "octomap-rt-server: LCM handle failed; intake stopped\n";
        failed_ = true;
        return;
      }
    }
  }
}

void ScanIntake::on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
  // Runs inside LCM's C dispatch: nothing may throw out of here.
  try {
    handled_++;
    const size_t producer = producers_.producer_for(channel);
    if (producers_.is_overflow(producer)) {
      producers_.count_rejected_arrival(producer, Reject::kTooManyProducers);
      return;
    }
    const auto received = Clock::now();
    QueuedScan item;
    const Reject why = validate_scan(static_cast<const uint8_t*>(rbuf->data), rbuf->data_size,
                                     producers_.expected_robot_id(producer), limits_, item.msg);
    if (why != Reject::kNone) {
      producers_.count_rejected_arrival(producer, why);
      return;
    }
    item.producer = producer;
    item.received = received;
    item.bytes = queued_bytes(item.msg);
    const int64_t seq = item.msg.seq, utime = item.msg.utime;
    producers_.admit(producer, seq, utime, [&] { return queue_.try_push(std::move(item)); });
  } catch (const std::exception& e) {
    std::cerr << "octomap-rt-server: unexpected error on " << channel << ": " << e.what() << "\n";
  }
}

}  // namespace ort::daemon
