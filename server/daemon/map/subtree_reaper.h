// Frees the nodes of evicted regions on its own thread (issue 25): eviction detaches a
// region's subtree from the tree under the map lock in O(1) (octree/region_codec.h
// detach_region) and hands it here, so stage 2 does not wait for thousands of deletes. The
// nodes are no longer in the tree, so nothing else refers to them. What waits here is bounded:
// past `max_queued_nodes`, push() frees in the caller (the memory is then freed before the
// call returns, as without the reaper).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <thread>

#include "octree/region_codec.h"

namespace ort::daemon {

class SubtreeReaper {
 public:
  explicit SubtreeReaper(uint64_t max_queued_nodes);
  ~SubtreeReaper();  // frees what is still queued
  SubtreeReaper(const SubtreeReaper&) = delete;
  SubtreeReaper& operator=(const SubtreeReaper&) = delete;

  void push(DetachedSubtree d);
  uint64_t queued_nodes() const;

 private:
  void run();

  const uint64_t max_queued_nodes_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<DetachedSubtree> queue_;
  uint64_t queued_nodes_ = 0;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace ort::daemon
