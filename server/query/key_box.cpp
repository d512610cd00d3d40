#include "query/key_box.h"

#include <cmath>
#include <string>

#include "query/query_types.h"

namespace ort::query {

int64_t KeyBox::voxels() const {
  int64_t n = 1;
  for (int i = 0; i < 3; ++i) n *= int64_t(max[i]) - int64_t(min[i]) + 1;
  return n;
}

bool checked_key(const octomap::OcTree& tree, double coordinate, octomap::key_type& key) {
  // The key range is [-2^(d-1), 2^(d-1)) resolutions; twice that is well inside int.
  const double far = tree.getResolution() * double(1u << tree.getTreeDepth());
  if (!(std::abs(coordinate) < far)) return false;  // NaN too
  return tree.coordToKeyChecked(coordinate, key);
}

bool checked_key(const octomap::OcTree& tree, const octomap::point3d& p, octomap::OcTreeKey& key) {
  for (unsigned i = 0; i < 3; ++i)
    if (!checked_key(tree, double(p(i)), key[i])) return false;
  return true;
}

octomap::key_type clamped_key(const octomap::OcTree& tree, double coordinate) {
  octomap::key_type k = 0;
  if (checked_key(tree, coordinate, k)) return k;
  // Outside the key range: one side or the other (finite coordinates only reach here).
  const int top = (1 << tree.getTreeDepth()) - 1;
  return coordinate < 0 ? octomap::key_type(0) : octomap::key_type(top);
}

KeyBox key_box(const octomap::OcTree& tree, const double lo[3], const double hi[3]) {
  static const char* axis = "xyz";
  KeyBox b;
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(lo[i]) || !std::isfinite(hi[i]))
      throw QueryError(std::string("box corner is not finite on ") + axis[i]);
    if (lo[i] > hi[i]) throw QueryError(std::string("box min > max on ") + axis[i]);
    b.min[i] = clamped_key(tree, lo[i]);
    b.max[i] = clamped_key(tree, hi[i]);
  }
  return b;
}

KeyBox key_box(const octomap::OcTree& tree, const octomap::point3d& lo, const octomap::point3d& hi) {
  // coordToKey(point3d) converts each float coordinate to double first: the same keys.
  const double l[3] = {lo.x(), lo.y(), lo.z()}, h[3] = {hi.x(), hi.y(), hi.z()};
  return key_box(tree, l, h);
}

NodeCube node_cube(const octomap::OcTreeKey& key, unsigned depth, unsigned tree_depth) {
  NodeCube c;
  c.side = 1 << (tree_depth - depth);
  const unsigned mask = ~unsigned(c.side - 1);
  for (int i = 0; i < 3; ++i) c.lo[i] = octomap::key_type(key[i] & mask);
  return c;
}

NodeCube child_cube(const NodeCube& cube, unsigned i) {
  NodeCube c;
  c.side = cube.side / 2;
  for (int a = 0; a < 3; ++a) c.lo[a] = octomap::key_type(cube.lo[a] + ((i >> a) & 1) * c.side);
  return c;
}

int64_t overlap_voxels(const NodeCube& c, const KeyBox& b) {
  int64_t n = 1;
  for (int i = 0; i < 3; ++i) {
    const int64_t lo = std::max<int64_t>(c.lo[i], b.min[i]);
    const int64_t hi = std::min<int64_t>(int64_t(c.lo[i]) + c.side - 1, b.max[i]);
    if (hi < lo) return 0;
    n *= hi - lo + 1;
  }
  return n;
}

bool cube_inside(const NodeCube& c, const KeyBox& b) {
  for (int i = 0; i < 3; ++i)
    if (c.lo[i] < b.min[i] || int64_t(c.lo[i]) + c.side - 1 > b.max[i]) return false;
  return true;
}

}  // namespace ort::query
