#include "daemon/intake/producer_registry.h"

#include <cstring>

#include "core/clock.h"
#include "protocol/ids.h"

namespace ort::daemon {
namespace {

ProducerPolicy make_policy(size_t max_producers) {
  ProducerPolicy p;
  p.max_producers = max_producers;
  return p;
}

}  // namespace

ProducerRegistry::ProducerRegistry(std::string scan_prefix, ProducerPolicy policy)
    : prefix_(std::move(scan_prefix)), policy_(std::move(policy)) {}

ProducerRegistry::ProducerRegistry(std::string scan_prefix, size_t max_producers)
    : ProducerRegistry(std::move(scan_prefix), make_policy(max_producers)) {}

std::string literal_prefix(const std::string& regex) {
  std::string out;
  for (char c : regex) {
    if (std::strchr(".[]{}()*+?^$|\\", c)) break;
    out += c;
  }
  return out;
}

size_t ProducerRegistry::special_entry(size_t& index, const char* channel, const char* robot_id) {
  if (index == SIZE_MAX) {
    index = producers_.size();
    ProducerStats s;
    s.channel = channel;
    s.robot_id = robot_id;
    producers_.push_back(s);
    last_arrival_.emplace_back();
    first_valid_.emplace_back();
  }
  return index;
}

bool ProducerRegistry::allowed(const std::string& robot_id) const {
  if (policy_.allowed_robots.empty()) return true;
  for (const std::string& id : policy_.allowed_robots)
    if (protocol::same_robot_id(id, robot_id)) return true;
  return false;
}

size_t ProducerRegistry::idle_slot(SteadyClock::time_point now) const {
  if (policy_.idle_release.count() <= 0) return SIZE_MAX;
  size_t best = SIZE_MAX;
  for (const auto& [channel, i] : by_channel_) {
    if (producers_[i].in_flight != 0 || now - last_arrival_[i] < policy_.idle_release) continue;
    if (best == SIZE_MAX || last_arrival_[i] < last_arrival_[best]) best = i;
  }
  return best;
}

void add_counts(ProducerStats& into, const ProducerStats& from) {
  into.received += from.received;
  into.applied += from.applied;
  into.rejected += from.rejected;
  into.dropped += from.dropped;
  into.missed += from.missed;
  into.points_applied += from.points_applied;
  into.seq_restarts += from.seq_restarts;
  for (size_t k = 0; k < kRejectReasonCount; ++k) {
    into.rejects[k] += from.rejects[k];
    into.drop_reasons[k] += from.drop_reasons[k];
  }
  for (size_t k = 0; k < kPointDropReasonCount; ++k) into.point_drops[k] += from.point_drops[k];
  into.points_read_as_zero += from.points_read_as_zero;
}

void ProducerRegistry::release(size_t slot) {
  ProducerStats& r = producers_[special_entry(released_index_, "-", "(released: idle)")];
  ProducerStats& p = producers_[slot];
  add_counts(r, p);
  r.released++;
  by_channel_.erase(p.channel);
  p = ProducerStats{};
  first_valid_[slot] = {};  // the new channel earns its own history
}

size_t ProducerRegistry::producer_for(const std::string& channel, SteadyClock::time_point now) {
  std::lock_guard lock(mutex_);
  if (auto it = by_channel_.find(channel); it != by_channel_.end()) {
    last_arrival_[it->second] = now;
    return it->second;
  }
  const std::string robot = channel.compare(0, prefix_.size(), prefix_) == 0 ? channel.substr(prefix_.size()) : channel;
  if (!allowed(robot)) return special_entry(refused_index_, "!", "(not allowed)");
  size_t slot = SIZE_MAX;
  if (slots_used_ < policy_.max_producers) {
    slot = producers_.size();
    producers_.emplace_back();
    last_arrival_.emplace_back();
    first_valid_.emplace_back();
    slots_used_++;
  } else if ((slot = idle_slot(now)) != SIZE_MAX) {
    release(slot);
  } else {
    return special_entry(overflow_index_, "*", "(other channels)");
  }
  producers_[slot].channel = channel;
  producers_[slot].robot_id = robot;
  last_arrival_[slot] = now;
  by_channel_.emplace(channel, slot);
  return slot;
}

bool ProducerRegistry::is_overflow(size_t producer) const {
  std::lock_guard lock(mutex_);
  return producer == overflow_index_ || producer == refused_index_;
}

Reject ProducerRegistry::refusal(size_t producer) const {
  std::lock_guard lock(mutex_);
  if (producer == overflow_index_) return Reject::kTooManyProducers;
  if (producer == refused_index_) return Reject::kRobotNotAllowed;
  return Reject::kNone;
}

std::string ProducerRegistry::expected_robot_id(size_t producer) const {
  std::lock_guard lock(mutex_);
  return producers_[producer].robot_id;
}

bool ProducerRegistry::has_history(size_t producer, SteadyClock::time_point now) const {
  std::lock_guard lock(mutex_);
  const ProducerStats& p = producers_[producer];
  const SteadyClock::time_point first = first_valid_[producer];
  return p.received - p.rejected >= policy_.history_scans && first != SteadyClock::time_point{} &&
         now - first >= policy_.history;
}

void ProducerRegistry::count_rejected_arrival(size_t producer, Reject why) {
  std::lock_guard lock(mutex_);
  ProducerStats& p = producers_[producer];
  p.received++;
  p.rejected++;
  p.rejects[static_cast<size_t>(why)]++;
}

void ProducerRegistry::note_seq(ProducerStats& p, int64_t seq) const {
  // Gaps are judged on every valid arrival (dropped ones included: they did arrive). The
  // step is computed with an overflow check: a hostile or corrupt seq (INT64_MAX after 0,
  // INT64_MIN after INT64_MAX) is a restart, never a wrapped count of missed scans.
  int64_t step = 0;
  if (!p.has_seq) {
    p.has_seq = true;
  } else if (__builtin_sub_overflow(seq, p.last_seq, &step) || step < 1 || step - 1 > policy_.max_seq_gap) {
    p.seq_restarts++;
  } else {
    p.missed += step - 1;
  }
  p.last_seq = seq;
}

bool ProducerRegistry::admit(size_t producer, int64_t seq, int64_t utime, const std::function<bool()>& enqueue) {
  std::lock_guard lock(mutex_);
  ProducerStats& p = producers_[producer];
  p.received++;
  if (p.has_seq && seq == p.last_seq && utime == p.last_utime) {
    p.rejected++;
    p.rejects[static_cast<size_t>(Reject::kDuplicateSeq)]++;
    return false;
  }
  note_seq(p, seq);
  p.last_utime = utime;
  if (first_valid_[producer] == SteadyClock::time_point{}) first_valid_[producer] = SteadyClock::now();
  if (!enqueue()) {
    p.dropped++;
    p.drop_reasons[static_cast<size_t>(Reject::kQueueFull)]++;
    return false;
  }
  p.in_flight++;
  return true;
}

void ProducerRegistry::count_applied(size_t producer, int64_t points, double end_to_end_ms,
                                     const PointDropCounts& dropped, int64_t read_as_zero) {
  std::lock_guard lock(mutex_);
  ProducerStats& p = producers_[producer];
  p.in_flight--;
  p.applied++;
  p.points_applied += points;
  for (size_t k = 0; k < kPointDropReasonCount; ++k) p.point_drops[k] += dropped[k];
  p.points_read_as_zero += read_as_zero;
  p.last_end_to_end_ms = end_to_end_ms;
}

void ProducerRegistry::count_rejected_in_flight(size_t producer, Reject why) {
  std::lock_guard lock(mutex_);
  ProducerStats& p = producers_[producer];
  p.in_flight--;
  p.rejected++;
  p.rejects[static_cast<size_t>(why)]++;
}

void ProducerRegistry::count_dropped_in_flight(size_t producer, Reject why) {
  std::lock_guard lock(mutex_);
  ProducerStats& p = producers_[producer];
  p.in_flight--;
  p.dropped++;
  p.drop_reasons[static_cast<size_t>(why)]++;
}

std::vector<ProducerStats> ProducerRegistry::snapshot() const {
  std::lock_guard lock(mutex_);
  return producers_;
}

}  // namespace ort::daemon
