#include "daemon/serving/map_snapshot.h"

#include <chrono>
#include <mutex>

#include "core/clock.h"
#include "daemon/map/map_residency.h"

namespace ort::daemon {
namespace {

// Under map.mutex.
MapCopy copy_locked(const MapState& map, SteadyClock::time_point t0) {
  MapCopy c;
  c.tree = std::make_unique<octomap::OcTree>(*map.tree);
  // With a memory bound the copy is the whole map: its stand-ins get their regions back.
  if (map.residency) map.residency->fill_copy(*c.tree);
  c.version = map.version;
  c.epoch = map.epoch;
  c.scans = map.scans;
  c.newest_scan = map.newest_scan;
  c.last_scan_utime = map.last_scan_utime;
  c.lock_ms = ms_since(t0);
  return c;
}

}  // namespace

MapCopy copy_map(MapState& map) {
  const auto t0 = SteadyClock::now();
  std::shared_lock lock(map.mutex);  // a reader: queries may read at the same time
  return copy_locked(map, t0);
}

std::optional<MapCopy> copy_map_if_changed(MapState& map, uint64_t unchanged_since) {
  const auto t0 = SteadyClock::now();
  std::shared_lock lock(map.mutex);  // a reader: queries may read at the same time
  if (map.version == unchanged_since) return std::nullopt;
  return copy_locked(map, t0);
}

}  // namespace ort::daemon
