// OctoMap's node counter (OcTree::size(), used by memoryUsage() and written into .ot files)
// is a plain size_t inside the tree that createNodeChild, expandNode, deleteNodeChild and
// pruneNode change. Threads that change one tree's nodes at once must not all go through
// that tree: each calls those methods on its own empty "counting" OcTree instead (they work
// on any node), whose size() then moves by the thread's net change. Afterwards one
// thread moves the sum into the real tree with the functions below, through the public API
// only, so the map stays a plain octomap::OcTree.
#pragma once

#include <cstdint>

#include <octomap/OcTree.h>

namespace ort {

// The net change of a counting tree's size() between two readings (modulo 2^64: a counting
// tree's count may well go "below zero").
inline int64_t counted_change(size_t size_after, size_t size_before) {
  return static_cast<int64_t>(size_after - size_before);
}

// Adds `delta` to tree.size() without changing tree's nodes, and marks the tree's extent as
// changed (OctoMap recomputes its metric bounds lazily after any node was created or
// deleted). Costs one allocation and one free per unit of |delta|: it creates (or deletes)
// children of a node that belongs to no tree, with `tree`'s methods, and undoes that with
// `helper`'s, an empty OcTree whose own count is of no interest.
void add_to_node_count(octomap::OcTree& tree, octomap::OcTree& helper, int64_t delta);

}  // namespace ort
