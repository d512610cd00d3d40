// A map edit on its way through the pipeline: queued with the scans (ScanQueue::push_edit),
// passed through stage 1 untouched, applied by stage 2 under the map lock between two scans,
// so it holds from the map state it reports on, in arrival order with the scans.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

#include "query/edit_cost.h"

namespace ort::daemon {

// Why an edit was not applied; the query service turns it into the ack's status.
enum class EditRefusal {
  kNone,        // applied
  kBadRequest,  // the box cannot be an edit of this map (query::QueryError)
  kTooCostly,   // its cost passes a bound (EditBounds): refused before it started
  kNotApplied,  // the server stopped before the edit's turn (drain deadline passed)
};

struct MapEditResult {
  bool ok = false;
  EditRefusal refusal = EditRefusal::kNone;
  std::string error;
  uint64_t version = 0;  // map state id right after the edit
  uint64_t epoch = 0;    // and its epoch (a reset starts a new one)
  int64_t map_utime = 0;
  int64_t voxels = 0;    // finest voxels of the box
  query::EditCost cost;  // as estimated before the edit (a clear)
  double locked_ms = 0;  // time under the map's exclusive lock, estimate included
};

struct MapEditItem {
  int8_t op = 0;  // map_edit_t.OP_*
  double box_min[3] = {0, 0, 0}, box_max[3] = {0, 0, 0};
  bool include_unknown = false;  // a clear to free marks the box's unknown voxels free too
  query::EditBounds bounds;      // past them the edit is refused, the map untouched
  // Called by stage 2 after the edit (outside the map lock).
  std::function<void(const MapEditResult&)> done;
};

// Applies the edit to the map (caller holds the map lock exclusively), or refuses it
// (kTooCostly) before changing anything. Throws query::QueryError for a bad box.
struct MapState;
MapEditResult apply_map_edit(MapState& map, const MapEditItem& edit);

// Tells the edit's sender that it was not applied (`why`), through its done callback.
void refuse_map_edit(const MapEditItem& edit, EditRefusal refusal, std::string why);

}  // namespace ort::daemon
