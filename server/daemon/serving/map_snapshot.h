// A consistent copy of the server's map: the tree as it was between two whole scans, taken
// under the map lock, with the map state id it was taken at. Saves serialize such a copy
// outside the lock (so stage 2 waits only for the copy); snapshots served over LCM will too.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>

#include <octomap/OcTree.h>

#include "daemon/map/map_state.h"

namespace ort::daemon {

struct MapCopy {
  std::unique_ptr<octomap::OcTree> tree;
  uint64_t version = 0;  // the map state id (MapState::version) the copy shows
  uint64_t epoch = 0;    // and its epoch
  size_t scans = 0;      // applied scans it contains (the first `scans` lines of the order)
  std::map<std::string, MapState::NewestScan> newest_scan;  // each robot's newest scan in it
  int64_t last_scan_utime = 0;                              // utime of the newest scan in it
  double lock_ms = 0;                                       // how long the copy held the map lock
};

// Copies the map under its lock. OcTree's copy constructor holds the lock for less time than
// serializing would (docs/BENCHMARKS.md, "Serving the map").
MapCopy copy_map(MapState& map);
// The same, unless the map's version is still `unchanged_since` (then nothing is copied).
std::optional<MapCopy> copy_map_if_changed(MapState& map, uint64_t unchanged_since);

}  // namespace ort::daemon
