// One map from the maps of a shard set (docs/PROTOCOL.md, "Shards"): the shards' trees hold
// disjoint regions (subtrees at the set's region depth), so the merged tree takes every node at
// or below the region depth from the one shard that has it, and makes the nodes above as
// OctoMap's own updates leave them: inner values the max of their children, eight equal leaf
// children pruned into their parent. On trees of one daemon's applied order that is the
// one-daemon tree node for node, and OcTree::writeBinary of it is that map's .bt byte for byte.
#pragma once

#include <memory>
#include <span>
#include <stdexcept>

#include <octomap/OcTree.h>

namespace ort::client {

// Two shards hold the same region, or the trees' resolutions differ.
class ShardMergeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The merged map of `shards` (nullptr entries are skipped; at least one is needed), with the
// first tree's resolution and sensor model. `region_depth`: the set's (1 .. 16).
std::unique_ptr<octomap::OcTree> merge_shard_trees(std::span<const octomap::OcTree* const> shards,
                                                   unsigned region_depth);

}  // namespace ort::client
