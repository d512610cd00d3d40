// Map edits: clear a key box to free or to unknown, and reset. They change the tree in
// place through OctoMap's public node API (createNodeChild, expandNode, pruneNode,
// deleteNodeChild on leaves only, so OcTree::size() stays exact), keep every inner node's
// value OctoMap's (the children's maximum) and leave the tree pruned where it was.
//
// A clear changes the box only: a leaf that straddles the box's border is split there, so
// the part outside keeps its value (octomap_server's clear_bbx sets such a leaf whole).
//
// Clear to free, known space only (Unknown::kKept, the default): every known finest voxel of
// the box becomes free with the clamping minimum's log-odds; unknown voxels stay unknown. The
// result equals OctoMap's setNodeValue(key, clamping min) for every key of the box that
// search() finds, then updateInnerOccupancy() and prune(). Clear to free with
// Unknown::kMarked: every voxel of the box, known or not (the caller says the space is free):
// setNodeValue for every key of the box. Clear to unknown: every voxel of the box is deleted;
// the result equals deleteNode(key) for every key of the box, then updateInnerOccupancy()
// (OctoMap's deleteNode leaves ancestors' values stale); a tree left without nodes is empty.
#pragma once

#include <octomap/OcTree.h>

#include "query/key_box.h"

namespace ort::query {

enum class ClearTo { kFree, kUnknown };
// What a clear to free does with the box's unknown voxels (no effect on a clear to unknown).
enum class Unknown { kKept, kMarked };

void clear_box(octomap::OcTree& tree, const KeyBox& box, ClearTo to, Unknown unknown = Unknown::kKept);
// An empty map of the same resolution and sensor model.
void reset_map(octomap::OcTree& tree);

}  // namespace ort::query
