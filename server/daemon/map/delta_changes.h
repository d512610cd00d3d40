// What a map delta carries, from the octree stage's change logs (octree/leaf_changes.h).
//
// The batched octree update logs every finest leaf it changes with its value before and after,
// so the classes before and after are known exactly: no look-up in the tree and no estimate.
// A change set spans several scans; a key may appear in several of them (and, after the
// updateNode loop, more than once in one): each record is classified on its own, the records
// are kept in the order applied, and keep_newest_per_key() leaves each key's newest value.
// In class mode that is the key's class after the set whenever its class changed somewhere in
// it (records that leave the class as it was are dropped, so the last kept one's new class is
// the final class); a key that changed class and changed back is sent with its (unchanged)
// class, harmless to a mirror.
#pragma once

#include <cstdint>
#include <vector>

#include "octree/leaf_changes.h"
#include "protocol/delta_codec.h"

namespace ort::daemon {

// Appends one scan's changes to `out`, in the log's order. Class mode: the leaves whose
// occupancy class changed (unknown -> free or occupied, free <-> occupied: log-odds against
// `occupancy_thres_log`, OctoMap's isNodeOccupied), with their new CLASS_*. Exact mode: every
// changed leaf with its new log-odds.
void append_delta_changes(const LeafChanges& scan, bool exact, float occupancy_thres_log,
                          std::vector<protocol::VoxelChange>& out);

// Sorts `set` by key and keeps the last value appended for each key.
void keep_newest_per_key(std::vector<protocol::VoxelChange>& set);

}  // namespace ort::daemon
