// Map edits: clear a key box to free or to unknown, and reset. They change the tree in
// place through OctoMap's public node API (createNodeChild, expandNode, pruneNode,
// deleteNodeChild on leaves only, so OcTree::size() stays exact), keep every inner node's
// value OctoMap's (the children's maximum) and leave the tree pruned where it was.
//
// Clear to free: every finest voxel of the box becomes free with the clamping minimum's
// log-odds (known or not before: the caller says the space is free). The result equals
// OctoMap's setNodeValue(key, clamping min) for every key of the box, then
// updateInnerOccupancy() and prune(). Clear to unknown: every voxel of the box is deleted;
// the result equals deleteNode(key) for every key of the box, then updateInnerOccupancy()
// (OctoMap's deleteNode leaves ancestors' values stale); a tree left without nodes is empty.
#pragma once

#include <octomap/OcTree.h>

#include "query/key_box.h"

namespace ort::query {

enum class ClearTo { kFree, kUnknown };

void clear_box(octomap::OcTree& tree, const KeyBox& box, ClearTo to);
// An empty map of the same resolution and sensor model.
void reset_map(octomap::OcTree& tree);

}  // namespace ort::query
