// An axis-aligned box of finest-level voxels, as inclusive key ranges, and the key cube a
// tree node covers. Everything the box queries count or extract is defined on these.
#pragma once

#include <algorithm>
#include <cstdint>

#include <octomap/OcTree.h>

namespace ort::query {

struct KeyBox {
  octomap::OcTreeKey min{0, 0, 0}, max{0, 0, 0};  // inclusive, min <= max per axis
  int64_t voxels() const;                         // (max - min + 1) per axis, multiplied
};

// The voxels of the metric box [lo, hi]: coordToKey of each corner (OctoMap's own
// rounding, the same keys as begin_leafs_bbx(lo, hi)), corners outside the key range
// clamped to its edge. Throws QueryError for a non-finite corner or lo > hi on an axis.
KeyBox key_box(const octomap::OcTree& tree, const octomap::point3d& lo, const octomap::point3d& hi);
// The same with double corners (the wire's box corners are doubles).
KeyBox key_box(const octomap::OcTree& tree, const double lo[3], const double hi[3]);

// The key cube of a node at `depth` that holds `key` (any key inside it, e.g. the center
// key an iterator reports): lowest key and side length in finest voxels.
struct NodeCube {
  octomap::OcTreeKey lo{0, 0, 0};  // (OcTreeKey's default constructor leaves it uninitialized)
  int side = 1;
};
NodeCube node_cube(const octomap::OcTreeKey& key, unsigned depth, unsigned tree_depth);
// Child i of a node covering `cube`: bit 0 of i is x, bit 1 is y, bit 2 is z (OctoMap's
// computeChildIdx order).
NodeCube child_cube(const NodeCube& cube, unsigned i);

// Finest voxels shared by a cube and a box (0 when they are disjoint).
int64_t overlap_voxels(const NodeCube& c, const KeyBox& b);
bool cube_inside(const NodeCube& c, const KeyBox& b);

// OctoMap's coordToKeyChecked without its undefined behaviour: 1.9.7 converts
// floor(coordinate / resolution) to int before it checks the range, which is undefined for
// coordinates far outside the map (found by fuzzing the query messages). Coordinates that
// far out are outside the key range, so the answer is the same: false.
bool checked_key(const octomap::OcTree& tree, double coordinate, octomap::key_type& key);
bool checked_key(const octomap::OcTree& tree, const octomap::point3d& p, octomap::OcTreeKey& key);

// coordToKey for one axis, clamped to [0, 2^tree_depth - 1] outside the key range.
octomap::key_type clamped_key(const octomap::OcTree& tree, double coordinate);

}  // namespace ort::query
