// A blocking hand-off of capacity N between two threads (stage 1 -> stage 2). With N = 1,
// stage 1 can shoot scan k+1 while stage 2 applies scan k, and is never further ahead:
// memory stays bounded and the applied order is the shot order.
#pragma once

#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>

namespace ort::daemon {

template <class T>
class BoundedHandoff {
 public:
  explicit BoundedHandoff(size_t capacity) : capacity_(capacity) {}

  void push(T&& v) {
    std::unique_lock lock(mutex_);
    not_full_.wait(lock, [&] { return items_.size() < capacity_; });
    items_.push_back(std::move(v));
    not_empty_.notify_one();
  }
  // nullopt once closed and empty.
  std::optional<T> pop() {
    std::unique_lock lock(mutex_);
    not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
    if (items_.empty()) return std::nullopt;
    T v = std::move(items_.front());
    items_.pop_front();
    not_full_.notify_one();
    return v;
  }
  void close() {
    std::lock_guard lock(mutex_);
    closed_ = true;
    not_empty_.notify_all();
  }
  size_t size() const {
    std::lock_guard lock(mutex_);
    return items_.size();
  }

 private:
  mutable std::mutex mutex_;
  std::condition_variable not_full_, not_empty_;
  std::deque<T> items_;
  size_t capacity_;
  bool closed_ = false;
};

}  // namespace ort::daemon
