#include "daemon/map/map_edit_item.h"

#include "daemon/map/map_identity.h"
#include "daemon/map/map_residency.h"
#include "daemon/map/map_state.h"
#include "octomap_rt/map_edit_t.hpp"
#include "query/map_edit.h"

namespace ort::daemon {

MapEditResult apply_map_edit(MapState& map, const MapEditItem& edit) {
  using Msg = octomap_rt::map_edit_t;
  MapEditResult r;
  octomap::OcTree& tree = *map.tree;
  if (edit.op == Msg::OP_RESET) {
    // An empty map is not the same history at a later id.
    apply_map_step(
        map, [](octomap::OcTree& t) { query::reset_map(t); }, /*forks_history=*/true);
    if (map.residency) map.residency->forget_all();
  } else {
    const query::KeyBox box = query::key_box(tree, edit.box_min, edit.box_max);
    // The box's spilled regions come back before the estimate reads them.
    if (map.residency) map.residency->touch_boxes(tree, std::span<const query::KeyBox>(&box, 1));
    r.voxels = box.voxels();
    const query::ClearTo to = edit.op == Msg::OP_CLEAR_TO_FREE ? query::ClearTo::kFree : query::ClearTo::kUnknown;
    const query::Unknown unknown = edit.include_unknown ? query::Unknown::kMarked : query::Unknown::kKept;
    r.cost = query::estimate_clear_box(tree, box, to, unknown, edit.bounds);
    if (r.cost.over) {
      const bool nodes = r.cost.new_nodes > edit.bounds.max_new_nodes;
      r.refusal = EditRefusal::kTooCostly;
      r.error = "too costly: the edit would " +
                (nodes ? "add more than " + std::to_string(edit.bounds.max_new_nodes) + " nodes (--max-edit-nodes)"
                       : "take more than " + std::to_string(edit.bounds.max_work) + " node visits (--max-edit-work)") +
                "; the map is unchanged";
      return r;
    }
    if (map.residency) map.residency->will_change(std::span<const query::KeyBox>(&box, 1));
    apply_map_step(map, [box, to, unknown](octomap::OcTree& t) { query::clear_box(t, box, to, unknown); });
    if (map.residency) map.residency->enforce(tree);
  }
  // Deltas cannot carry an edit (a box back to unknown, a reset): mirrors resync from a snapshot.
  if (map.observer) map.observer->replaced(tree, map.version, map.epoch);
  r.ok = true;
  r.version = map.version;
  r.epoch = map.epoch;
  r.map_utime = map.last_scan_utime;
  return r;
}

void refuse_map_edit(const MapEditItem& edit, EditRefusal refusal, std::string why) {
  MapEditResult r;
  r.refusal = refusal;
  r.error = std::move(why);
  if (edit.done) edit.done(r);
}

}  // namespace ort::daemon
