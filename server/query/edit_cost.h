// What a clear_box (query/map_edit.h) would cost, found before it starts, so that an edit past
// its bound is refused instead of building millions of nodes under the map's exclusive lock.
//
// new_nodes: nodes the edit adds to the tree at most (an upper bound: splitting a leaf that
// straddles the box's border makes 8 children at every level down to the finest where a cube
// straddles it; a clear to free that marks unknown space makes them all the way from the root).
// work: nodes the edit visits, plus the nodes it makes and frees again on the way (a deleted
// node costs a split and a prune: OctoMap's public way to free it), plus new_nodes: the time
// the edit holds the lock for grows with it.
//
// The estimate walks the existing nodes that overlap the box, and stops once the work passes
// its bound (over = true): it costs at most about max_work node visits itself.
#pragma once

#include <cstdint>

#include <octomap/OcTree.h>

#include "query/key_box.h"
#include "query/map_edit.h"

namespace ort::query {

struct EditBounds {
  int64_t max_new_nodes = 0;
  int64_t max_work = 0;
};

struct EditCost {
  int64_t new_nodes = 0;
  int64_t work = 0;
  bool over = false;  // a bound is passed (the counts are then lower bounds)
};

EditCost estimate_clear_box(const octomap::OcTree& tree, const KeyBox& box, ClearTo to, Unknown unknown,
                            const EditBounds& bounds);

// Cubes of side 2 and more, within `cube` (side a power of two, aligned to it), that overlap the
// box without lying inside it: each is a node a clear splits into 8.
int64_t straddling_cubes(const NodeCube& cube, const KeyBox& box);

}  // namespace ort::query
