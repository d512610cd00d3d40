// The LCM thread. It owns every call to handle (LCM allows only one handling thread) and
// does nothing slow: an UNTYPED subscription hands it raw bytes, which it validates (wire
// checks before decode, decode in try/catch, then content), counts, and queues. Shutdown:
// the thread poll()s LCM's fd together with an eventfd that stop() writes, and drains LCM
// with handleTimeout(0), so it never blocks inside LCM.
#pragma once

#include <atomic>
#include <string>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "daemon/producer_registry.h"
#include "daemon/scan_queue.h"
#include "daemon/scan_validation.h"

namespace ort::daemon {

class ScanIntake {
 public:
  ScanIntake(lcm::LCM& lc, std::string channel_regex, const ScanLimits& limits, ProducerRegistry& producers,
             ScanQueue& queue, int lcm_queue_capacity);
  ~ScanIntake();
  ScanIntake(const ScanIntake&) = delete;
  ScanIntake& operator=(const ScanIntake&) = delete;

  // Subscribes (before the thread starts: 1.3.1's subscribe races with handle), then starts
  // the thread. Throws std::runtime_error when LCM cannot subscribe.
  void start();
  // Stops the thread and unsubscribes; messages not yet handled by then are not received.
  void stop();
  // Set when LCM's handle failed (the thread then exits).
  bool failed() const { return failed_; }
  int64_t messages_handled() const { return handled_; }

 private:
  void run();
  void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel);

  lcm::LCM& lc_;
  std::string regex_;
  ScanLimits limits_;
  ProducerRegistry& producers_;
  ScanQueue& queue_;
  int lcm_queue_capacity_;
  lcm::Subscription* sub_ = nullptr;
  int wake_fd_ = -1;
  std::thread thread_;
  std::atomic<bool> failed_{false};
  std::atomic<int64_t> handled_{0};
};

}  // namespace ort::daemon
