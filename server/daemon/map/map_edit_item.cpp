#include "daemon/map/map_edit_item.h"

#include "daemon/map/map_state.h"
#include "octomap_rt/map_edit_t.hpp"
#include "query/map_edit.h"

namespace ort::daemon {

MapEditResult apply_map_edit(MapState& map, const MapEditItem& edit) {
  using Msg = octomap_rt::map_edit_t;
  MapEditResult r;
  octomap::OcTree& tree = *map.tree;
  if (edit.op == Msg::OP_RESET) {
    query::reset_map(tree);
  } else {
    const query::KeyBox box = query::key_box(tree, edit.box_min, edit.box_max);
    r.voxels = box.voxels();
    query::clear_box(tree, box, edit.op == Msg::OP_CLEAR_TO_FREE ? query::ClearTo::kFree : query::ClearTo::kUnknown);
  }
  map.version++;
  // Deltas cannot carry an edit (a box back to unknown, a reset): mirrors resync from a snapshot.
  if (map.observer) map.observer->replaced(tree, map.version);
  r.ok = true;
  r.version = map.version;
  r.map_utime = map.last_scan_utime;
  return r;
}

}  // namespace ort::daemon
