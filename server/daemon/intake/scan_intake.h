// The scan intake: a raw handler on the server's LCM loop. It does nothing slow: the
// untyped subscription hands it raw bytes, which it validates (wire checks before decode,
// decode in try/catch, then content), counts per producer, and queues for the pipeline.
#pragma once

#include <string>

#include "daemon/intake/producer_registry.h"
#include "daemon/intake/scan_queue.h"
#include "daemon/intake/scan_validation.h"
#include "daemon/transport/lcm_loop.h"

namespace ort::daemon {

class ScanIntake {
 public:
  ScanIntake(LcmLoop& loop, std::string channel_regex, const ScanLimits& limits, ProducerRegistry& producers,
             ScanQueue& queue, int lcm_queue_capacity);
  ~ScanIntake();
  ScanIntake(const ScanIntake&) = delete;
  ScanIntake& operator=(const ScanIntake&) = delete;

  // Subscribes on the loop (call before the loop starts, so that no scan is missed).
  // Throws std::runtime_error when LCM cannot subscribe.
  void open();
  // Unsubscribes: after it returns no scan is queued any more, and scans arriving later are
  // not received (nor counted). Idempotent.
  void close();

 private:
  void on_message(const lcm::ReceiveBuffer& rbuf, const std::string& channel);

  LcmLoop& loop_;
  std::string regex_;
  ScanLimits limits_;
  ProducerRegistry& producers_;
  ScanQueue& queue_;
  int lcm_queue_capacity_;
  LcmLoop::SubscriptionId sub_ = 0;
};

}  // namespace ort::daemon
