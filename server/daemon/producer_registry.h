// Per-producer counters: every message on a scan channel is counted once as received and
// ends as applied, rejected (with its reason) or dropped; until then it is "in flight"
// (queued or in the pipeline). So at every instant, for every producer:
//   received = applied + rejected + dropped + in_flight.
// One mutex guards all of it; the LCM thread and the pipeline stages call in briefly.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "daemon/reject_reason.h"

namespace ort::daemon {

struct ProducerStats {
  std::string channel;
  std::string robot_id;        // the channel's suffix (what robot_id must match)
  int64_t received = 0, applied = 0, rejected = 0, dropped = 0, missed = 0;
  int64_t in_flight = 0;       // accepted, not yet applied or rejected
  int64_t points_applied = 0;
  int64_t last_seq = -1, last_utime = 0;
  int64_t seq_restarts = 0;    // seq went backwards: the producer restarted (not a gap)
  double last_end_to_end_ms = 0;
  std::array<int64_t, kRejectReasonCount> rejects{};
};

class ProducerRegistry {
 public:
  // `scan_prefix`: the literal start of every scan channel; the rest is the robot id.
  ProducerRegistry(std::string scan_prefix, size_t max_producers);

  // Index of the producer on `channel`, made on first sight. Past max_producers, every new
  // channel shares one overflow entry (channel "*"), whose scans are all rejected.
  size_t producer_for(const std::string& channel);
  bool is_overflow(size_t producer) const { return producer == overflow_index_; }
  std::string expected_robot_id(size_t producer) const;

  void count_rejected_arrival(size_t producer, Reject why);
  // A valid scan arrived: counts it and its seq gap, then calls `enqueue` under the
  // registry's lock; `enqueue` returns false when the queue refuses it (counted as dropped).
  // Returns whether it was queued.
  bool admit(size_t producer, int64_t seq, int64_t utime, const std::function<bool()>& enqueue);

  void count_applied(size_t producer, int64_t points, double end_to_end_ms);
  void count_rejected_in_flight(size_t producer, Reject why);

  std::vector<ProducerStats> snapshot() const;

 private:
  ProducerStats& at(size_t i) { return producers_[i]; }

  mutable std::mutex mutex_;
  std::string prefix_;
  size_t max_producers_;
  size_t overflow_index_ = SIZE_MAX;
  std::vector<ProducerStats> producers_;
  std::map<std::string, size_t> by_channel_;
};

// The literal prefix of a channel regex: its characters up to the first regex
// metacharacter ("OCTOMAP_RT_SCAN_.*" -> "OCTOMAP_RT_SCAN_").
std::string literal_prefix(const std::string& regex);

}  // namespace ort::daemon
