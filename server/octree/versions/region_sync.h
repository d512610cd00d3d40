// Making one tree equal to another a slice at a time, for the read replica's rebuild after it
// fell behind (daemon/map/map_replica.h): each slice runs under a short shared lock of the
// source, which may change between slices.
//
// A slice walks the nodes above the region depth (octree/region.h) and makes the copy's equal
// to the source's (values, children, coarse leaves), and copies whole the regions named dirty
// (or that the copy lacks) until its budget of copied nodes is spent. Regions not dirty are
// taken as equal: the caller names dirty every region a change touched since its last copy
// (all of them to start with). A slice that copied every dirty region it met leaves the copy
// equal to the source node for node (its .ot bytes too: tests/server/map_replica_test.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <unordered_set>

#include <octomap/OcTree.h>

#include "octree/region.h"

namespace ort {

struct RegionSyncSlice {
  uint64_t nodes_copied = 0, regions_copied = 0;
  bool done = false;  // every dirty region met was copied: the copy equals the source now
};

// An empty tree with the source's resolution and sensor model, to sync into.
std::unique_ptr<octomap::OcTree> empty_tree_like(const octomap::OcTree& src);

// One slice (see above). `dirty` loses the regions it copied; one it met but had no budget
// left for stays. Throws std::invalid_argument if `dst` has another resolution.
RegionSyncSlice sync_slice(const octomap::OcTree& src, octomap::OcTree& dst, const RegionGrid& grid,
                           std::unordered_set<RegionId>& dirty, uint64_t budget_nodes);

}  // namespace ort
