// What a query may read, as key boxes: the memory bound (daemon/map/map_residency.h) brings
// back every evicted region these meet before the query is answered, so an answer is the one
// the whole map gives. Conservative: points their voxel, boxes and grids their box, a ray
// every region its segment passes (to its range, or to the key range's edge without one), a
// distance query what it reads (its box, points or path grown by its clamp distance); a
// kind of query not listed in query_footprint.cpp, the whole map.
#pragma once

#include <vector>

#include <octomap/OcTree.h>

#include "daemon/queries/query_clients.h"
#include "octree/region.h"
#include "query/key_box.h"

namespace ort::daemon {

// Never throws: a query the map cannot answer (a non-finite box, ...) has no footprint, and
// its answer is the refusal it gets without the bound.
std::vector<query::KeyBox> query_footprint(const octomap::OcTree& tree, const RegionGrid& grid, const QueryMessage& q);

}  // namespace ort::daemon
