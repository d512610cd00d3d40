// The map's size for the status (nodes, leaves, memory, version, epoch), read without holding
// the octree stage up. size() is O(1); the leaf count comes from the map's running count
// (MapState::leaves: the octree stage says how each scan changed the leaves, a reset leaves
// none), so a status never walks the tree while scans are applied. Only after a change that
// does not say (a clear-box, a decay or clearing slice, an eviction or restore) is the count
// forgotten, and then counted again by a walk here: on the read replica when there is one
// (the octree stage never waits for that walk; the map of record takes the replica's count
// once both are at one state id), else on the map of record under its lock. Such walks are
// spaced so that they take at most 1/kWalkDutyDivisor of the time (a map whose walk takes 1 s
// is counted at most every 20 s), maps up to kLeafWalkEveryStatus nodes at every status,
// and once more when the pipeline has drained (the summary's figures are exact). Memory comes
// from the leaf count with OctoMap's formula.
//
// Usage: read() from any thread (calls are serialized). It never waits long for a map lock: a
// stage stuck while holding it must still be reported (DEGRADED), so after ~100 ms the last
// figures are used again.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>

#include "core/clock.h"
#include "daemon/map/map_state.h"

namespace ort::daemon {

struct MapSize {
  int64_t version = 0, epoch = 0, nodes = 0, leaves = 0, memory_bytes = 0;
};

class MapFigures {
 public:
  // `pipeline_drained`: no scan will change the map any more (count the leaves now).
  MapSize read(MapState& map, bool pipeline_drained);

 private:
  // Maps up to this size have a forgotten leaf count counted again at every status (a short
  // hold of the map lock even on the 2-core dev machine).
  static constexpr size_t kLeafWalkEveryStatus = 65'536;
  static constexpr int kWalkDutyDivisor = 20;

  // Whether a forgotten count of `tree` is counted again now, and the count (then remembered
  // in `leaves`). Caller holds a shared lock of the tree's map.
  bool recount(const octomap::OcTree& tree, std::atomic<int64_t>& leaves, bool pipeline_drained);

  // Written by whichever thread gathers a status (the status thread and any caller of
  // MappingServer::status()); the map locks they take are shared, so this serializes them.
  std::mutex mutex_;
  size_t leaves_ = 0;
  int64_t nodes_ = 0, memory_ = 0, version_ = 0, epoch_ = 0;
  SteadyClock::time_point walked_at_;  // when the last walk ended
  double walk_ms_ = 0;                 // how long it took
};

}  // namespace ort::daemon
