#include "daemon/intake/scan_intake.h"

#include "core/clock.h"
#include "daemon/intake/scan_to_map.h"

namespace ort::daemon {

ScanIntake::ScanIntake(LcmLoop& loop, std::string channel_regex, const ScanLimits& limits, ProducerRegistry& producers,
                       ScanQueue& queue, int lcm_queue_capacity)
    : loop_(loop),
      regex_(std::move(channel_regex)),
      limits_(limits),
      producers_(producers),
      queue_(queue),
      lcm_queue_capacity_(lcm_queue_capacity) {}

ScanIntake::~ScanIntake() {
  try {
    close();
  } catch (...) {}
}

void ScanIntake::open() {
  if (sub_) return;
  // LCM's own queue drops silently when full (lcm-proj/lcm#345); our handler is quick, so a
  // moderate capacity suffices and bounds LCM's memory.
  sub_ = loop_.subscribe(
      regex_, [this](const lcm::ReceiveBuffer& rbuf, const std::string& channel) { on_message(rbuf, channel); },
      lcm_queue_capacity_);
}

void ScanIntake::close() {
  if (!sub_) return;
  loop_.unsubscribe(sub_);
  sub_ = 0;
}

void ScanIntake::on_message(const lcm::ReceiveBuffer& rbuf, const std::string& channel) {
  const size_t producer = producers_.producer_for(channel);
  if (producers_.is_overflow(producer)) {
    producers_.count_rejected_arrival(producer, producers_.refusal(producer));
    return;
  }
  const auto received = SteadyClock::now();
  QueuedScan item;
  const Reject why = validate_scan(static_cast<const uint8_t*>(rbuf.data), rbuf.data_size,
                                   producers_.expected_robot_id(producer), limits_, item.msg);
  if (why != Reject::kNone) {
    producers_.count_rejected_arrival(producer, why);
    return;
  }
  item.producer = producer;
  item.established = producers_.has_history(producer, received);
  item.received = received;
  item.decoded = SteadyClock::now();
  item.bytes = queued_bytes(item.msg);
  // Its walk, for the queue's prediction of what it will cost the stages (intake/stage_cost_model.h).
  const RayLengths rays =
      ray_lengths(item.msg, effective_max_range(item.msg.max_range, limits_.max_range), limits_.resolution);
  item.walk_voxels = rays.total_voxels;
  item.mean_ray_voxels = rays.mean_voxels();
  const int64_t seq = item.msg.seq, utime = item.msg.utime;
  producers_.admit(producer, seq, utime, [&] { return queue_.try_push(std::move(item)); });
}

}  // namespace ort::daemon
