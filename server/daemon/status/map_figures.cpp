#include "daemon/status/map_figures.h"

#include <algorithm>
#include <chrono>
#include <shared_mutex>
#include <thread>

#include "daemon/map/map_replica.h"

namespace ort::daemon {

MapSize MapFigures::read(MapState& map, bool pipeline_drained) {
  std::lock_guard cache_lock(mutex_);
  if (map.replica) {
    MapState& r = map.replica->state();
    std::shared_lock rl(r.mutex, std::defer_lock);
    for (int i = 0; i < 100 && !rl.try_lock(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const auto now = SteadyClock::now();
    if (rl.owns_lock() && static_cast<int64_t>(r.version) != leaves_version_ &&
        (leaves_version_ < 0 || pipeline_drained || now - leaves_time_ >= std::chrono::seconds(1))) {
      leaves_ = r.tree->getNumLeafNodes();
      leaves_time_ = now;
      leaves_version_ = static_cast<int64_t>(r.version);
    }
  }
  std::shared_lock lock(map.mutex, std::defer_lock);
  for (int i = 0; i < 100 && !lock.try_lock(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  if (lock.owns_lock()) {
    const octomap::OcTree& t = *map.tree;
    const auto now = SteadyClock::now();
    const int64_t version = static_cast<int64_t>(map.version);
    if (!map.replica && version != leaves_version_ &&
        (t.size() <= kLeafWalkEveryStatus || pipeline_drained || now - leaves_time_ > std::chrono::seconds(10))) {
      leaves_ = t.getNumLeafNodes();
      leaves_time_ = now;
      leaves_version_ = version;
    }
    const size_t leaves = std::min(leaves_, t.size());
    nodes_ = static_cast<int64_t>(t.size());
    version_ = static_cast<int64_t>(map.version);
    epoch_ = static_cast<int64_t>(map.epoch);
    memory_ = static_cast<int64_t>(sizeof(octomap::OcTree) + t.memoryUsageNode() * t.size() +
                                   (t.size() - leaves) * sizeof(octomap::OcTreeNode* [8]));
  }
  MapSize s;
  s.version = version_;
  s.epoch = epoch_;
  s.nodes = nodes_;
  s.leaves = static_cast<int64_t>(std::min<size_t>(leaves_, static_cast<size_t>(nodes_)));
  s.memory_bytes = memory_;
  return s;
}

}  // namespace ort::daemon
