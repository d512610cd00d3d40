#include "daemon/status/map_figures.h"

#include <algorithm>
#include <chrono>
#include <shared_mutex>
#include <thread>

#include "daemon/map/map_replica.h"

namespace ort::daemon {
namespace {

// A shared lock of `m`, tried for ~100 ms (not owned after that).
std::shared_lock<MapMutex> try_shared(MapMutex& m) {
  std::shared_lock lock(m, std::defer_lock);
  for (int i = 0; i < 100 && !lock.try_lock(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return lock;
}

}  // namespace

bool MapFigures::recount(const octomap::OcTree& tree, std::atomic<int64_t>& leaves, bool pipeline_drained) {
  const auto now = SteadyClock::now();
  const bool due = tree.size() <= kLeafWalkEveryStatus || pipeline_drained || walked_at_ == SteadyClock::time_point{} ||
                   std::chrono::duration<double, std::milli>(now - walked_at_).count() >= kWalkDutyDivisor * walk_ms_;
  if (!due) return false;
  leaves.store(static_cast<int64_t>(tree.getNumLeafNodes()), std::memory_order_relaxed);
  walked_at_ = SteadyClock::now();
  walk_ms_ = ms_between(now, walked_at_);
  return true;
}

MapSize MapFigures::read(MapState& map, bool pipeline_drained) {
  std::lock_guard cache_lock(mutex_);
  // The replica first, without the map of record's lock: a walk there holds only the
  // replica's readers' lock, never the octree stage.
  int64_t replica_leaves = -1;
  uint64_t replica_version = 0;
  if (map.replica) {
    MapState& r = map.replica->state();
    if (std::shared_lock rl = try_shared(r.mutex); rl.owns_lock()) {
      const MapHoldNote note(r.holders, "status (leaf count)");
      if (r.leaves.load(std::memory_order_relaxed) < 0) recount(*r.tree, r.leaves, pipeline_drained);
      replica_leaves = r.leaves.load(std::memory_order_relaxed);
      replica_version = r.version;
    }
  }
  if (std::shared_lock lock = try_shared(map.mutex); lock.owns_lock()) {
    const MapHoldNote note(map.holders, "status (map size)");
    const octomap::OcTree& t = *map.tree;
    // Two trees at one state id are the same tree: the map of record takes the replica's count.
    if (map.leaves.load(std::memory_order_relaxed) < 0 && replica_leaves >= 0 && replica_version == map.version)
      map.leaves.store(replica_leaves, std::memory_order_relaxed);
    if (map.leaves.load(std::memory_order_relaxed) < 0 && !map.replica) recount(t, map.leaves, pipeline_drained);
    if (const int64_t n = map.leaves.load(std::memory_order_relaxed); n >= 0)
      leaves_ = static_cast<size_t>(n);
    else if (replica_leaves >= 0)
      leaves_ = static_cast<size_t>(replica_leaves);  // the replica's, a few scans behind
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
