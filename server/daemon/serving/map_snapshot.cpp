#include "daemon/serving/map_snapshot.h"

#include <chrono>
#include <mutex>

#include "core/clock.h"
#include "daemon/map/map_residency.h"

namespace ort::daemon {
namespace {

// Under map.mutex. With a memory bound, `spilled` gets the bytes of every region the copy has
// a stand-in for (read under the same lock, so they are the copy's).
MapCopy copy_locked(const MapState& map, SteadyClock::time_point t0, MapResidency::SpilledRegions& spilled) {
  MapCopy c;
  c.tree = std::make_unique<octomap::OcTree>(*map.tree);
  if (map.residency) spilled = map.residency->spilled_regions();
  c.version = map.version;
  c.epoch = map.epoch;
  c.scans = map.scans;
  c.newest_scan = map.newest_scan;
  c.last_scan_utime = map.last_scan_utime;
  c.lock_ms = ms_since(t0);
  return c;
}

// With a memory bound the copy is the whole map: its stand-ins get their regions back, after
// the lock is let go (the rebuild is most of a bounded copy's time).
void fill_spilled(const MapState& map, MapCopy& c, const MapResidency::SpilledRegions& spilled) {
  if (map.residency && !spilled.empty()) MapResidency::fill_copy(*c.tree, map.residency->grid(), spilled);
}

}  // namespace

MapCopy copy_map(MapState& map) {
  const auto t0 = SteadyClock::now();
  MapResidency::SpilledRegions spilled;
  MapCopy c;
  {
    std::shared_lock lock(map.mutex);  // a reader: queries may read at the same time
    const MapHoldNote note(map.holders, "map copy (snapshot, save)");
    c = copy_locked(map, t0, spilled);
  }
  fill_spilled(map, c, spilled);
  return c;
}

std::optional<MapCopy> copy_map_if_changed(MapState& map, uint64_t unchanged_since) {
  const auto t0 = SteadyClock::now();
  MapResidency::SpilledRegions spilled;
  MapCopy c;
  {
    std::shared_lock lock(map.mutex);  // a reader: queries may read at the same time
    const MapHoldNote note(map.holders, "map copy (viewer map)");
    if (map.version == unchanged_since) return std::nullopt;
    c = copy_locked(map, t0, spilled);
  }
  fill_spilled(map, c, spilled);
  return c;
}

}  // namespace ort::daemon
