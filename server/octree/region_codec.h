// A region's subtree as bytes, for the memory bound's spill to disk (issue 25): eviction
// keeps the region's root node in the tree as a childless stand-in holding its value (the max
// of its subtree, which is what it held before), so every node above stays as it was, and
// moves the nodes below it into bytes; restoring puts them back node for node.
//
// Format (little-endian): "ORTR" magic, u32 version (1), u64 region id, u32 region depth,
// u64 node count, u64 FNV-1a-64 of the body, then the body: the subtree in pre-order, each
// node a float log-odds and a byte of child bits (bit i: child i follows).
//
// A region in stand-in form must be restored before anything reads or changes its voxels:
// the stand-in looks like one coarse leaf to OctoMap's code.
#pragma once

#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include <octomap/OcTree.h>

#include "octree/region.h"

namespace ort {

class RegionCodecError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The bytes of region `id`'s subtree (its root at the region depth, which must exist and
// have children; throws RegionCodecError otherwise).
std::vector<uint8_t> encode_region(const octomap::OcTree& tree, const RegionGrid& grid, RegionId id);

// The bytes of region `id` at `depth` from its subtree already laid out as the body above
// (OctoMap's .ot writes nodes the same way: a float and a byte of child bits, in pre-order),
// so a map file's region goes to the spill without being built as a tree first.
std::vector<uint8_t> region_bytes_from_body(RegionId id, unsigned depth, std::span<const uint8_t> body);

// Deletes every node below region `id`'s root (the root stays, as a childless stand-in with
// its value). Returns the nodes freed.
uint64_t strip_region(octomap::OcTree& tree, const RegionGrid& grid, RegionId id);

// Region `id`'s nodes below its root taken out of the tree at once (the root stays as the
// childless stand-in strip_region leaves; the tree's node counter goes down by `nodes`), to
// be freed later on any thread by free_detached: nothing in the tree refers to them any more,
// so freeing them need not hold up the tree's writer.
struct DetachedSubtree {
  octomap::AbstractOcTreeNode** children = nullptr;  // the root's child array, as it was
  uint64_t nodes = 0;                                // nodes below the root
};
// `nodes_below`: the subtree's nodes without its root (an encoding's count minus one).
DetachedSubtree detach_region(octomap::OcTree& tree, const RegionGrid& grid, RegionId id, uint64_t nodes_below);
void free_detached(DetachedSubtree& d);
// The nodes below region `id`'s root, and the inner nodes of its subtree (the root with them),
// as detach_region and OctoMap's memoryUsage() count them (0, 0 without a subtree).
struct SubtreeSize {
  uint64_t nodes_below = 0, inner = 0;
};
SubtreeSize region_size(const octomap::OcTree& tree, const RegionGrid& grid, RegionId id);
// The bytes encode_region gives for a region whose subtree was detached, from its stand-in's
// value and the detached nodes, without the tree: any thread may call it while nothing
// changes or frees those nodes.
std::vector<uint8_t> encode_detached(RegionId id, unsigned depth, float root_log_odds, const DetachedSubtree& d);
// Puts a detached subtree back below region `id`'s stand-in (the tree's node counter goes up
// by d.nodes; `d` is emptied). Throws RegionCodecError (tree unchanged) without a stand-in.
void reattach_region(octomap::OcTree& tree, const RegionGrid& grid, RegionId id, DetachedSubtree& d);

// Puts the subtree of `bytes` back below region `id`'s stand-in (a childless node at the
// region depth). Throws RegionCodecError when the bytes are not a whole region of this id
// and depth (checksum, sizes, shape) or the stand-in is not there; the tree is then unchanged.
void restore_region(octomap::OcTree& tree, const RegionGrid& grid, RegionId id, std::span<const uint8_t> bytes);

// The region id and node count in a region's header (RegionCodecError if it is not one).
struct RegionHeader {
  RegionId id = 0;
  unsigned depth = 0;
  uint64_t nodes = 0;
};
RegionHeader read_region_header(std::span<const uint8_t> bytes);

// Checks the header and checksum only.
bool region_bytes_intact(std::span<const uint8_t> bytes);

}  // namespace ort
