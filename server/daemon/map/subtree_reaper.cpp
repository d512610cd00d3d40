#include "daemon/map/subtree_reaper.h"

namespace ort::daemon {

SubtreeReaper::SubtreeReaper(uint64_t max_queued_nodes)
    : max_queued_nodes_(max_queued_nodes), thread_([this] { run(); }) {}

SubtreeReaper::~SubtreeReaper() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
  for (DetachedSubtree& d : queue_) free_detached(d);
}

void SubtreeReaper::push(DetachedSubtree d) {
  if (d.children == nullptr) return;
  {
    std::lock_guard lock(mutex_);
    if (queued_nodes_ + d.nodes <= max_queued_nodes_) {
      queued_nodes_ += d.nodes;
      queue_.push_back(d);
      d = {};
    }
  }
  if (d.children == nullptr) return wake_.notify_one();
  free_detached(d);  // the queue is full: freed here
}

uint64_t SubtreeReaper::queued_nodes() const {
  std::lock_guard lock(mutex_);
  return queued_nodes_;
}

void SubtreeReaper::run() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (stopping_) return;
    DetachedSubtree d = queue_.front();
    queue_.pop_front();
    const uint64_t nodes = d.nodes;
    lock.unlock();
    free_detached(d);
    lock.lock();
    queued_nodes_ -= nodes;
  }
}

}  // namespace ort::daemon
