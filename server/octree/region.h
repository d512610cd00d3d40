// Regions: the subtrees of the octree at one fixed depth, the house's one unit for work on
// part of a map (decay and clearing in slices, eviction to disk, readers, shards).
//
// A region at depth d is the cube of keys that share their top d bits: its id packs the
// three key coordinates shifted right by (tree depth - d), so region_of is a shift and a
// pack, and neighbouring keys share a region exactly as they share OctoMap's node at depth d.
// Where the tree stores a leaf coarser than d (a pruned node above the region depth), that
// leaf covers several regions at once: the walks below report it once, as a "coarse leaf",
// so a caller that changes leaves never changes one twice.
#pragma once

#include <cstdint>
#include <vector>

#include <octomap/OcTree.h>

namespace ort {

// The packed coordinates of a region (16 bits an axis: z << 32 | y << 16 | x).
using RegionId = uint64_t;

struct RegionGrid {
  // Depth of the region roots below the tree's root: 1 .. 16 (OctoMap's tree depth). Depth
  // 10 at 0.1 m gives regions of 64 keys, 6.4 m, a side.
  unsigned depth = 10;

  unsigned shift() const { return 16 - depth; }
  // Keys a side of one region.
  unsigned side_keys() const { return 1u << shift(); }
};

// The grid for `depth` (throws std::invalid_argument outside 1 .. 16).
RegionGrid region_grid(unsigned depth);

RegionId region_of(const RegionGrid& grid, const octomap::OcTreeKey& key);

// The key coordinates of a region's corner voxels (inclusive).
octomap::OcTreeKey region_min_key(const RegionGrid& grid, RegionId id);
octomap::OcTreeKey region_max_key(const RegionGrid& grid, RegionId id);

// A region's extent: keys inclusive, metres from the min corner of its first voxel to the
// max corner of its last.
struct RegionBounds {
  octomap::OcTreeKey min_key, max_key;
  octomap::point3d min, max;
};
RegionBounds region_bounds(const octomap::OcTree& tree, const RegionGrid& grid, RegionId id);

// What the tree holds for one region: its root node at the region depth, or the stored
// leaf above it that covers it (depth < grid.depth), or nothing (node nullptr).
struct RegionNode {
  octomap::OcTreeNode* node = nullptr;
  octomap::OcTreeNode* parent = nullptr;  // node's parent; nullptr when node is the root
  unsigned child_index = 0;               // node's index in parent
  unsigned depth = 0;                     // node's depth
};
RegionNode find_region(const octomap::OcTree& tree, const RegionGrid& grid, RegionId id);

// One stored leaf as the walks report it: its node, the key of its min-corner voxel and
// its depth (16: a finest voxel). OctoMap's keyToCoord(key, depth) gives its centre.
struct RegionLeaf {
  const octomap::OcTreeNode* node;
  octomap::OcTreeKey key;
  unsigned depth;
};

// Calls f(RegionLeaf) for every stored leaf inside region `id`, in child-index order. A
// leaf coarser than the region that covers it is reported once, at its own depth.
template <class F>
void for_each_leaf_in_region(const octomap::OcTree& tree, const RegionGrid& grid, RegionId id, F&& f);

// Calls f(RegionId, const RegionNode&) for every region holding a node, and once for every
// coarse leaf above the region depth (with the id of the region of its min-corner key and
// node.depth < grid.depth), in child-index order from the root: the same order for the
// same tree. Visits only the nodes above the region depth.
template <class F>
void for_each_region(const octomap::OcTree& tree, const RegionGrid& grid, F&& f);

// The ids for_each_region visits, in its order (coarse leaves included).
std::vector<RegionId> list_regions(const octomap::OcTree& tree, const RegionGrid& grid);

// --- implementation ---
namespace detail {
inline octomap::OcTreeKey child_min_key(const octomap::OcTreeKey& parent_min, unsigned parent_depth, unsigned i) {
  const uint16_t half = static_cast<uint16_t>(1u << (16 - parent_depth - 1));
  octomap::OcTreeKey k = parent_min;
  if (i & 1) k[0] = static_cast<uint16_t>(k[0] + half);
  if (i & 2) k[1] = static_cast<uint16_t>(k[1] + half);
  if (i & 4) k[2] = static_cast<uint16_t>(k[2] + half);
  return k;
}

template <class F>
void leaves_below(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const octomap::OcTreeKey& min_key,
                  unsigned depth, F& f) {
  if (!tree.nodeHasChildren(node)) {
    f(RegionLeaf{node, min_key, depth});
    return;
  }
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(node, i))
      leaves_below(tree, tree.getNodeChild(node, i), child_min_key(min_key, depth, i), depth + 1, f);
}

template <class F>
void regions_below(const octomap::OcTree& tree, const RegionGrid& grid, octomap::OcTreeNode* parent, unsigned index,
                   octomap::OcTreeNode* node, const octomap::OcTreeKey& min_key, unsigned depth, F& f) {
  if (depth == grid.depth || !tree.nodeHasChildren(node)) {
    f(region_of(grid, min_key), RegionNode{node, parent, index, depth});
    return;
  }
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(node, i))
      regions_below(tree, grid, node, i, const_cast<octomap::OcTreeNode*>(tree.getNodeChild(node, i)),
                    child_min_key(min_key, depth, i), depth + 1, f);
}
}  // namespace detail

template <class F>
void for_each_leaf_in_region(const octomap::OcTree& tree, const RegionGrid& grid, RegionId id, F&& f) {
  const RegionNode r = find_region(tree, grid, id);
  if (r.node == nullptr) return;
  const octomap::OcTreeKey region_min = region_min_key(grid, id);
  if (r.depth < grid.depth) {  // a coarse leaf: its own min corner
    const uint16_t mask = static_cast<uint16_t>(~((1u << (16 - r.depth)) - 1));
    const octomap::OcTreeKey k(region_min[0] & mask, region_min[1] & mask, region_min[2] & mask);
    f(RegionLeaf{r.node, k, r.depth});
    return;
  }
  detail::leaves_below(tree, r.node, region_min, r.depth, f);
}

template <class F>
void for_each_region(const octomap::OcTree& tree, const RegionGrid& grid, F&& f) {
  octomap::OcTreeNode* root = const_cast<octomap::OcTree&>(tree).getRoot();
  if (root == nullptr) return;
  detail::regions_below(tree, grid, nullptr, 0, root, octomap::OcTreeKey(0, 0, 0), 0, f);
}

}  // namespace ort
