// OctoMap's node counter (OcTree::size(), used by memoryUsage() and written into .ot files)
// is a plain size_t inside the tree (OcTreeBaseImpl::tree_size, protected) that
// createNodeChild, expandNode, deleteNodeChild and pruneNode change. Threads that change one
// tree's nodes at once must not all go through that tree: each calls those methods on its
// own empty "counting" OcTree instead (they work on any node), whose counter then holds the
// thread's net change; afterwards the sum is added to the real tree's counter in O(1).
//
// Why an accessor and not a subclass of OcTree for the map: the counter lives in the base
// class, so a subclass would add nothing but its type, and that type would have to reach
// every place that makes or reads the map (MapEngine, `octomap-rt build`, the bench, the
// daemon's map_store, which loads FILE.ot through AbstractOcTree::read and so always gets a
// plain OcTree back, since the file's id "OcTree" names OcTree's registered prototype). The
// accessor below is a class derived from OcTree that is never instantiated: a derived class
// may form a pointer to a protected member of its base ([class.protected]), and that pointer
// applies to any OcTree. So the map stays a plain octomap::OcTree, its .ot files keep the id
// "OcTree", and nothing but this file knows about the counter.
#pragma once

#include <cstdint>

#include <octomap/OcTree.h>

namespace ort {

// Adds `delta` to tree.size() without changing tree's nodes, and marks the tree's extent as
// changed (OctoMap recomputes its metric bounds lazily after any node was created or
// deleted; nodes made through a counting tree did not tell `tree`).
void add_to_node_count(octomap::OcTree& tree, int64_t delta);

// The net number of nodes made (made minus deleted) through `counting` since the last call,
// and the counter back at zero. `counting` must hold no root (its counter then counts only
// what other trees' nodes were changed by through it).
int64_t take_node_count(octomap::OcTree& counting);

}  // namespace ort
