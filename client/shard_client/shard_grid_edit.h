// Grids and map edits across a shard set (docs/PROTOCOL.md, "Shards"). A grid cell is
// occupied if any voxel of its column in the band is, free if any is free and none occupied
// (octomap_server's projected_map rule, query/projected_grid.h); the shards' voxels are
// disjoint, so the set's cell is the most of the shards' cells (occupied > free > unknown),
// on the union of their extents (cells line up: every shard's grid has a cell boundary at
// x = 0 and y = 0). An edit goes to the shards owning a region its box meets (every shard for
// a reset) and holds when each of them applied it.
#pragma once

#include <vector>

#include "query_client/query_client.h"

namespace ort::client {

// The shards' grids of one band and cell size (nullptr: no answer) merged on the union of
// their extents. Throws std::invalid_argument when their cell sizes differ.
Grid merge_grids(const std::vector<const Grid*>& got);

}  // namespace ort::client
