// One region's subtree as OctoMap's .ot records (OcTreeBaseImpl::writeNodesRecurs: a node's
// log-odds, a byte of child bits, then its children depth first in child order), written
// from the tree whole, or merged from the region's records of the last version: where the
// tree changed only in a few cells of the region, the records of the subtrees that did not
// change are copied from the old bytes (read by their child bits, no tree walk) and only the
// changed cells are written from the tree. So a version costs the replica's thread in
// proportion to what changed (a copy and a scan of the old bytes elsewhere), not to the nodes
// of the regions touched.
#pragma once

#include <bitset>
#include <cstdint>
#include <string>

#include <octomap/OcTree.h>

namespace ort {

// The leaves' extent as OctoMap's const getMetricMin/Max compute it on a copy of the tree
// (the leaf iterator's key and depth: centre minus and plus half the node size, in doubles).
// Only leaves that may reach the extent are computed in doubles: a leaf whose first key lies
// past the smallest first key seen (or whose last key before the largest last key) cannot,
// since one key is a resolution and the doubles' rounding far less.
struct LeafExtent {
  double min[3], max[3];
  int64_t lo[3], hi[3];  // the smallest first key and the largest last key of the leaves seen
  LeafExtent();
  void add(const octomap::OcTree& tree, const octomap::OcTreeKey& key, unsigned depth);
};

struct RegionBytes {
  std::string bytes;
  uint64_t nodes = 0;
  double min[3], max[3];
};

// The cells of a region a change touched: its nodes `kCellLevels` levels below the region's
// root (fewer where the tree's depth ends sooner), numbered in child order (the records' order).
inline constexpr unsigned kCellLevels = 3;
using RegionCells = std::bitset<(1u << (3 * kCellLevels))>;
unsigned cell_levels(unsigned region_depth);
unsigned cell_of(const octomap::OcTreeKey& key, unsigned region_depth);

// The region whose root is `node` (at `key`, `depth` = the region depth), written whole.
void write_region(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const octomap::OcTreeKey& key,
                  unsigned depth, RegionBytes& out);
// The same, from `old` (the region's records when it was last written) and the tree, where
// only the cells in `changed` may differ since. Returns how many of its nodes were copied.
uint64_t merge_region(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const octomap::OcTreeKey& key,
                      unsigned depth, const RegionBytes& old, const RegionCells& changed, RegionBytes& out);

// Calls fn(child, child's key) for each existing child of `node` (at `depth`, key `key`), in
// OctoMap's child order: the order writeNodesRecurs writes them.
inline constexpr octomap::key_type kRootKey = 32768;  // OcTreeBaseImpl's tree_max_val at depth 16
template <class Fn>
void for_each_child(const octomap::OcTree& tree, const octomap::OcTreeNode* node, const octomap::OcTreeKey& key,
                    unsigned depth, Fn&& fn) {
  const octomap::key_type offset = kRootKey >> (depth + 1);
  for (unsigned i = 0; i < 8; ++i)
    if (tree.nodeChildExists(node, i)) {
      octomap::OcTreeKey child;
      octomap::computeChildKey(i, offset, key, child);
      fn(tree.getNodeChild(node, i), child);
    }
}

// One node's .ot record (OcTreeNode::writeData, then the child bits).
void append_record(std::string& out, const octomap::OcTree& tree, const octomap::OcTreeNode* node);

}  // namespace ort
