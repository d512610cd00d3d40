#include "octree/region.h"

#include <stdexcept>
#include <string>

namespace ort {

RegionGrid region_grid(unsigned depth) {
  if (depth < 1 || depth > 16)
    throw std::invalid_argument("region depth " + std::to_string(depth) + " is outside 1 .. 16");
  return RegionGrid{depth};
}

RegionId region_of(const RegionGrid& grid, const octomap::OcTreeKey& key) {
  const unsigned s = grid.shift();
  return RegionId(key[0] >> s) | RegionId(key[1] >> s) << 16 | RegionId(key[2] >> s) << 32;
}

octomap::OcTreeKey region_min_key(const RegionGrid& grid, RegionId id) {
  const unsigned s = grid.shift();
  return octomap::OcTreeKey(static_cast<uint16_t>((id & 0xffff) << s), static_cast<uint16_t>((id >> 16 & 0xffff) << s),
                            static_cast<uint16_t>((id >> 32 & 0xffff) << s));
}

octomap::OcTreeKey region_max_key(const RegionGrid& grid, RegionId id) {
  const octomap::OcTreeKey k = region_min_key(grid, id);
  const unsigned last = grid.side_keys() - 1;
  return octomap::OcTreeKey(static_cast<uint16_t>(k[0] + last), static_cast<uint16_t>(k[1] + last),
                            static_cast<uint16_t>(k[2] + last));
}

RegionBounds region_bounds(const octomap::OcTree& tree, const RegionGrid& grid, RegionId id) {
  RegionBounds b;
  b.min_key = region_min_key(grid, id);
  b.max_key = region_max_key(grid, id);
  const double half = tree.getResolution() / 2;
  for (unsigned a = 0; a < 3; ++a) {
    b.min(a) = static_cast<float>(tree.keyToCoord(b.min_key[a]) - half);
    b.max(a) = static_cast<float>(tree.keyToCoord(b.max_key[a]) + half);
  }
  return b;
}

RegionNode find_region(const octomap::OcTree& tree, const RegionGrid& grid, RegionId id) {
  RegionNode r;
  octomap::OcTreeNode* node = const_cast<octomap::OcTree&>(tree).getRoot();
  if (node == nullptr) return r;
  const octomap::OcTreeKey key = region_min_key(grid, id);
  unsigned depth = 0;
  while (depth < grid.depth && tree.nodeHasChildren(node)) {
    // OctoMap's child index at depth d: bit (15 - d) of each coordinate.
    const unsigned bit = 15 - depth;
    const unsigned i = ((key[0] >> bit) & 1) | ((key[1] >> bit) & 1) << 1 | ((key[2] >> bit) & 1) << 2;
    if (!tree.nodeChildExists(node, i)) return RegionNode{};
    r.parent = node;
    r.child_index = i;
    node = const_cast<octomap::OcTreeNode*>(tree.getNodeChild(node, i));
    ++depth;
  }
  r.node = node;
  r.depth = depth;
  return r;
}

std::vector<RegionId> list_regions(const octomap::OcTree& tree, const RegionGrid& grid) {
  std::vector<RegionId> ids;
  for_each_region(tree, grid, [&](RegionId id, const RegionNode&) { ids.push_back(id); });
  return ids;
}

}  // namespace ort
