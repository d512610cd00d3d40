// Per-producer counters: every message on a scan channel is counted once as received and
// ends as applied, rejected (with its reason) or dropped; until then it is "in flight"
// (queued or in the pipeline). So at every instant, for every producer:
//   received = applied + rejected + dropped + in_flight.
// One mutex guards all of it; the LCM thread and the pipeline stages call in briefly.
//
// Admission of channels (LCM has no authentication: anyone on the group may publish on any
// channel, see docs/RELIABILITY.md): with an allow-list only the listed robots get a slot;
// at most max_producers slots exist, and a slot whose producer has been idle (no message,
// nothing in flight) for idle_release is handed to a new channel, its counters folded into
// one "released" entry so that the sums still balance.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "core/clock.h"
#include "daemon/intake/reject_reason.h"

namespace ort::daemon {

struct ProducerStats {
  std::string channel;
  std::string robot_id;  // the channel's suffix (what robot_id must match)
  int64_t received = 0, applied = 0, rejected = 0, dropped = 0, missed = 0;
  int64_t in_flight = 0;  // accepted, not yet applied or rejected
  int64_t points_applied = 0;
  int64_t last_seq = -1, last_utime = 0;
  bool has_seq = false;      // a valid scan was seen (last_seq is meaningful)
  int64_t seq_restarts = 0;  // seq went backwards or jumped: the producer restarted (not a gap)
  int64_t released = 0;      // (released entry only) slots let go after being idle
  double last_end_to_end_ms = 0;
  std::array<int64_t, kRejectReasonCount> rejects{};
  std::array<int64_t, kRejectReasonCount> drop_reasons{};  // why dropped (queue full, shed, ...)
  PointDropCounts point_drops{};    // points of applied scans that gave no ray, by reason (NaN no-returns, ...)
  int64_t points_read_as_zero = 0;  // points of applied scans with a coordinate below 1e-20 m, read as 0
};

// The counters of `from` (received ... point drops, not the ids, in-flight or last-scan
// fields) added to `into`: how a released slot folds into the "released" entry.
void add_counts(ProducerStats& into, const ProducerStats& from);

struct ProducerPolicy {
  size_t max_producers = 64;
  // A producer with no message for this long (and nothing in flight) gives its slot to a
  // new channel when all slots are taken. <= 0: never.
  std::chrono::duration<double> idle_release{600.0};
  // Robot ids (case-insensitive) that may publish; empty: every valid id.
  std::vector<std::string> allowed_robots;
  // A seq step larger than this is a restart (counted), not that many lost scans.
  int64_t max_seq_gap = 100'000;
  // A producer has history (a share of the stages of its own, intake/scan_queue.h) once it
  // has sent this many valid scans over at least this long. Valid arrivals, not applied
  // scans: a flood in the shared class must not keep a new robot from ever earning its own.
  int64_t history_scans = 10;
  std::chrono::duration<double> history{5.0};
};

class ProducerRegistry {
 public:
  // `scan_prefix`: the literal start of every scan channel; the rest is the robot id.
  ProducerRegistry(std::string scan_prefix, ProducerPolicy policy);
  ProducerRegistry(std::string scan_prefix, size_t max_producers);

  // Index of the producer on `channel`, made on first sight (or in an idle slot). Channels
  // that get no slot share one of two refused entries: robots not on the allow-list
  // (channel "!"), and channels beyond max_producers (channel "*").
  size_t producer_for(const std::string& channel, SteadyClock::time_point now = SteadyClock::now());
  // True for the two refused entries; refusal() says which reason their scans get.
  bool is_overflow(size_t producer) const;
  Reject refusal(size_t producer) const;
  std::string expected_robot_id(size_t producer) const;
  // The producer has sent history_scans valid scans (received, not rejected), the first
  // history ago or earlier.
  bool has_history(size_t producer, SteadyClock::time_point now = SteadyClock::now()) const;

  void count_rejected_arrival(size_t producer, Reject why);
  // A valid scan arrived: counts it and its seq gap, then calls `enqueue` under the
  // registry's lock; `enqueue` returns false when the queue refuses it (counted as dropped:
  // queue full). A copy of the producer's previous scan (the same seq and utime: a message
  // delivered or replayed twice) is rejected (duplicate seq), never applied twice. Returns
  // whether it was queued.
  bool admit(size_t producer, int64_t seq, int64_t utime, const std::function<bool()>& enqueue);

  // A scan was applied: `points` of its points became rays, `dropped` gave none (by reason),
  // `read_as_zero` had a coordinate below 1e-20 m (core/prepare_scan.h).
  void count_applied(size_t producer, int64_t points, double end_to_end_ms, const PointDropCounts& dropped = {},
                     int64_t read_as_zero = 0);
  void count_rejected_in_flight(size_t producer, Reject why);
  // An accepted scan left the queue without being applied (shed, or left at stop).
  void count_dropped_in_flight(size_t producer, Reject why);

  std::vector<ProducerStats> snapshot() const;

 private:
  size_t special_entry(size_t& index, const char* channel, const char* robot_id);
  bool allowed(const std::string& robot_id) const;
  // A slot idle since before `now - idle_release`, or SIZE_MAX.
  size_t idle_slot(SteadyClock::time_point now) const;
  void release(size_t slot);
  void note_seq(ProducerStats& p, int64_t seq) const;

  mutable std::mutex mutex_;
  std::string prefix_;
  ProducerPolicy policy_;
  size_t overflow_index_ = SIZE_MAX, refused_index_ = SIZE_MAX, released_index_ = SIZE_MAX;
  size_t slots_used_ = 0;
  std::vector<ProducerStats> producers_;
  std::vector<SteadyClock::time_point> last_arrival_;  // parallel to producers_
  std::vector<SteadyClock::time_point> first_valid_;   // parallel to producers_; unset: none yet
  std::map<std::string, size_t> by_channel_;
};

// The literal prefix of a channel regex: its characters up to the first regex
// metacharacter ("OCTOMAP_RT_SCAN_.*" -> "OCTOMAP_RT_SCAN_").
std::string literal_prefix(const std::string& regex);

}  // namespace ort::daemon
