#include "daemon/producer_registry.h"

#include <cstring>

namespace ort::daemon {

ProducerRegistry::ProducerRegistry(std::string scan_prefix, size_t max_producers)
    : prefix_(std::move(scan_prefix)), max_producers_(max_producers) {}

std::string literal_prefix(const std::string& regex) {
  std::string out;
  for (char c : regex) {
    if (std::strchr(".[]{}()*+?^$|\\", c)) break;
    out += c;
  }
  return out;
}

size_t ProducerRegistry::producer_for(const std::string& channel) {
  std::lock_guard lock(mutex_);
  if (auto it = by_channel_.find(channel); it != by_channel_.end()) return it->second;
  if (producers_.size() >= max_producers_) {
    if (overflow_index_ == SIZE_MAX) {
      overflow_index_ = producers_.size();
      ProducerStats s;
      s.channel = "*";
      s.robot_id = "(other channels)";
      producers_.push_back(s);
    }
    return overflow_index_;
  }
  ProducerStats s;
  s.channel = channel;
  s.robot_id = channel.compare(0, prefix_.size(), prefix_) == 0 ? channel.substr(prefix_.size()) : channel;
  producers_.push_back(s);
  by_channel_.emplace(channel, producers_.size() - 1);
  return producers_.size() - 1;
}

std::string ProducerRegistry::expected_robot_id(size_t producer) const {
  std::lock_guard lock(mutex_);
  return producers_[producer].robot_id;
}

void ProducerRegistry::count_rejected_arrival(size_t producer, Reject why) {
  std::lock_guard lock(mutex_);
  ProducerStats& p = at(producer);
  p.received++;
  p.rejected++;
  p.rejects[static_cast<size_t>(why)]++;
}

bool ProducerRegistry::admit(size_t producer, int64_t seq, int64_t utime, const std::function<bool()>& enqueue) {
  std::lock_guard lock(mutex_);
  ProducerStats& p = at(producer);
  p.received++;
  // Gaps are judged on every valid arrival (dropped ones included: they did arrive).
  if (p.last_seq >= 0 && seq > p.last_seq + 1) p.missed += seq - p.last_seq - 1;
  if (p.last_seq >= 0 && seq <= p.last_seq) p.seq_restarts++;
  p.last_seq = seq;
  p.last_utime = utime;
  if (!enqueue()) {
    p.dropped++;
    return false;
  }
  p.in_flight++;
  return true;
}

void ProducerRegistry::count_applied(size_t producer, int64_t points, double end_to_end_ms) {
  std::lock_guard lock(mutex_);
  ProducerStats& p = at(producer);
  p.in_flight--;
  p.applied++;
  p.points_applied += points;
  p.last_end_to_end_ms = end_to_end_ms;
}

void ProducerRegistry::count_rejected_in_flight(size_t producer, Reject why) {
  std::lock_guard lock(mutex_);
  ProducerStats& p = at(producer);
  p.in_flight--;
  p.rejected++;
  p.rejects[static_cast<size_t>(why)]++;
}

std::vector<ProducerStats> ProducerRegistry::snapshot() const {
  std::lock_guard lock(mutex_);
  return producers_;
}

}  // namespace ort::daemon
