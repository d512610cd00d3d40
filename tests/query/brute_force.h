// Reference answers written from the definitions, voxel by voxel, with OctoMap's search():
// what the fast query code must reproduce exactly.
#pragma once

#include <random>
#include <set>
#include <tuple>

#include <octomap/OcTree.h>

#include "query/key_box.h"
#include "query/query_types.h"

namespace ort::test {

// search(key) at the finest level: no node = unknown, else isNodeOccupied.
query::VoxelState voxel_state(const octomap::OcTree& t, const octomap::OcTreeKey& key);
// One search per voxel of the box (use for boxes of up to a few 10^5 voxels).
query::BoxCounts brute_counts(const octomap::OcTree& t, const query::KeyBox& box);
// Every stored leaf of the whole tree (begin_leafs, no bbx iterator), the voxels it shares
// with the box computed from its center key and size: for boxes of any size.
query::BoxCounts all_leaves_counts(const octomap::OcTree& t, const query::KeyBox& box);

// Region reference: for every depth-`depth` cell touching the box, search(key in the cell
// and the box, depth); the distinct nodes found as (lo x, lo y, lo z, depth, state).
using RegionEntry = std::tuple<int, int, int, int, int>;
std::set<RegionEntry> brute_region(const octomap::OcTree& t, const query::KeyBox& box, unsigned depth,
                                   bool include_free);

// Random key box: every size from 1 voxel to the whole map, anywhere around it.
query::KeyBox random_box(const octomap::OcTree& t, std::mt19937& rng, int max_side);

}  // namespace ort::test
