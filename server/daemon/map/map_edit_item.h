// A map edit on its way through the pipeline: queued with the scans (ScanQueue::push_edit),
// passed through stage 1 untouched, applied by stage 2 under the map lock between two scans,
// so it holds from the map state it reports on, in arrival order with the scans.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace ort::daemon {

struct MapEditResult {
  bool ok = false;
  std::string error;
  uint64_t version = 0;  // map state id right after the edit
  int64_t map_utime = 0;
  int64_t voxels = 0;  // finest voxels of the box
};

struct MapEditItem {
  int8_t op = 0;  // map_edit_t.OP_*
  double box_min[3] = {0, 0, 0}, box_max[3] = {0, 0, 0};
  // Called by stage 2 after the edit (outside the map lock).
  std::function<void(const MapEditResult&)> done;
};

// Applies the edit to the map (caller holds the map lock exclusively). Throws
// query::QueryError for a bad box.
struct MapState;
MapEditResult apply_map_edit(MapState& map, const MapEditItem& edit);

}  // namespace ort::daemon
