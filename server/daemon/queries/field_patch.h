// The distance field cache's grid brought up to date from the map's change lists
// (daemon/map/change_journal.h) instead of read from the map again: under the map lock, the
// read of a cached box then costs the voxels that changed class since the entry's state, not
// the box's cells, and the changed cells are known without comparing grids.
#pragma once

#include <optional>

#include <octomap/OcTree.h>

#include "daemon/map/change_journal.h"
#include "distance/field_cache.h"

namespace ort::daemon {

// The patch that takes grid `box` (of `opt`) at map state `from` to the state of `tree`, `to`:
// a cell of one voxel takes its voxel's class from the journal (a scan leaves no voxel unknown,
// so it is an obstacle exactly when occupied, whatever `opt.unknown`); a coarser cell is read
// again from the tree. None (read the grid) when the journal cannot say (a state in between
// that was not a scan, or too old), when the changes (map-wide) are many (more than the box's
// cells and 2^18: the read is then as cheap), or for a shard's share of the obstacles.
std::optional<distance::GridPatch> patch_from_journal(ChangeJournal& journal, const octomap::OcTree& tree,
                                                      const distance::CellBox& box,
                                                      const distance::DistanceOptions& opt, uint64_t from, uint64_t to);

}  // namespace ort::daemon
