#include "daemon/intake/scan_queue.h"

#include <algorithm>
#include <iterator>
#include <string>

#include "core/clock.h"

namespace ort::daemon {

size_t queued_bytes(const octomap_rt::scan_t& msg) {
  return sizeof(QueuedScan) + msg.xyz.capacity() * sizeof(float) + msg.robot_id.size() + msg.map_frame.size();
}

ScanQueue::ScanQueue(uint64_t per_producer_budget, uint64_t total_budget)
    : per_producer_budget_(per_producer_budget), total_budget_(total_budget) {}

bool ScanQueue::try_push(QueuedScan&& s) {
  {
    std::lock_guard lock(mutex_);
    if (closed_) return false;
    if (s.producer >= bytes_by_producer_.size()) {
      bytes_by_producer_.resize(s.producer + 1, 0);
      depth_by_producer_.resize(s.producer + 1, 0);
    }
    if (bytes_by_producer_[s.producer] + s.bytes > per_producer_budget_) return false;
    if (total_bytes_ + s.bytes > total_budget_) return false;
    bytes_by_producer_[s.producer] += s.bytes;
    depth_by_producer_[s.producer]++;
    total_bytes_ += s.bytes;
    s.arrival = next_arrival_++;
    fifo_.push_back(std::move(s));
  }
  ready_.notify_one();
  return true;
}

bool ScanQueue::push_edit(std::shared_ptr<MapEditItem> edit) {
  {
    std::lock_guard lock(mutex_);
    if (closed_) return false;
    QueuedScan s;
    s.edit = std::move(edit);
    s.received = SteadyClock::now();
    s.arrival = next_arrival_++;
    fifo_.push_back(std::move(s));
  }
  ready_.notify_one();
  return true;
}

std::optional<QueuedScan> ScanQueue::pop() {
  std::unique_lock lock(mutex_);
  ready_.wait(lock, [&] { return closed_ || !fifo_.empty(); });
  if (fifo_.empty()) return std::nullopt;
  QueuedScan s = std::move(fifo_.front());
  fifo_.pop_front();
  if (s.edit) return s;
  bytes_by_producer_[s.producer] -= s.bytes;
  depth_by_producer_[s.producer]--;
  total_bytes_ -= s.bytes;
  return s;
}

std::vector<QueuedScan> ScanQueue::take_all() {
  std::lock_guard lock(mutex_);
  std::vector<QueuedScan> out(std::make_move_iterator(fifo_.begin()), std::make_move_iterator(fifo_.end()));
  fifo_.clear();
  std::fill(bytes_by_producer_.begin(), bytes_by_producer_.end(), 0);
  std::fill(depth_by_producer_.begin(), depth_by_producer_.end(), 0);
  total_bytes_ = 0;
  return out;
}

SteadyClock::duration ScanQueue::oldest_age(SteadyClock::time_point now) const {
  std::lock_guard lock(mutex_);
  return fifo_.empty() ? SteadyClock::duration::zero() : now - fifo_.front().received;
}

void ScanQueue::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  ready_.notify_all();
}

size_t ScanQueue::depth() const {
  std::lock_guard lock(mutex_);
  return fifo_.size();
}

uint64_t ScanQueue::bytes() const {
  std::lock_guard lock(mutex_);
  return total_bytes_;
}

uint64_t ScanQueue::producer_bytes(size_t producer) const {
  std::lock_guard lock(mutex_);
  return producer < bytes_by_producer_.size() ? bytes_by_producer_[producer] : 0;
}

size_t ScanQueue::producer_depth(size_t producer) const {
  std::lock_guard lock(mutex_);
  return producer < depth_by_producer_.size() ? depth_by_producer_[producer] : 0;
}

std::string ScanQueue::policy() const {
  return "per-producer byte budget " + std::to_string(per_producer_budget_ >> 20) + " MiB (total " +
         std::to_string(total_budget_ >> 20) +
         " MiB); when full the newest scan is dropped (counted as dropped: queue full); queued scans are "
         "never evicted, so scans are applied in arrival order";
}

}  // namespace ort::daemon
