// The map's size for the status (nodes, leaves, memory, version, epoch), read without holding
// the octree stage up. size() is O(1); the leaf count (and memoryUsage(), which needs it)
// walks the whole tree under the map lock, stalling stage 2 for the whole walk (on big maps,
// several scans' end-to-end time at every status). So the leaves are counted only when the
// map changed, and then on maps above kLeafWalkEveryStatus nodes at most every 10 s while
// scans are applied, and once more when the pipeline has drained (the summary's figures are
// exact); memory comes from the cached leaf count with OctoMap's formula. With the read
// replica the leaves are counted there (the octree stage never waits for the walk), whenever
// the map changed and at most once a second.
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
  // Maps up to this size have their leaves counted at every status (a short hold of the map
  // lock even on the 2-core dev machine).
  static constexpr size_t kLeafWalkEveryStatus = 65'536;

  // Written by whichever thread gathers a status (the status thread and any caller of
  // MappingServer::status()); the map locks they take are shared, so this serializes them.
  std::mutex mutex_;
  size_t leaves_ = 0;
  int64_t nodes_ = 0, memory_ = 0, version_ = 0, epoch_ = 0;
  SteadyClock::time_point leaves_time_;
  int64_t leaves_version_ = -1;  // map version of leaves_
};

}  // namespace ort::daemon
