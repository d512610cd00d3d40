// Child nodes made the way OcTreeBaseImpl::createNodeChild makes them, inline: the batched
// update makes about one node per voxel, and createNodeChild (out of line, through the tree
// object, counting every node in it) cost about 30 instructions a node beside the allocations.
//
// The node's child array is a protected member of OctoMap's OcTreeDataNode; as in
// node_count.h, a class derived from OcTreeNode that is never instantiated forms a pointer to
// that member ([class.protected]), which applies to any OcTreeNode. The array and the node
// come from plain new (`new AbstractOcTreeNode*[8]`, zeroed, and `new OcTreeNode()`, as
// createNodeChild makes them), so OctoMap's own code reads, prunes and deletes them.
#pragma once

#include <octomap/OcTree.h>

namespace ort {
namespace detail {
// Never instantiated: only its right to name OcTreeDataNode's protected child array.
struct ChildArrayAccess : octomap::OcTreeNode {
  static octomap::AbstractOcTreeNode**& of(octomap::OcTreeNode& node) { return node.*(&ChildArrayAccess::children); }
};
}  // namespace detail

// Whether `node` has its child array: a node made in this update and not yet given a child
// has none (only deleteNodeChild leaves an empty array behind, and this update never calls it).
inline bool has_child_array(octomap::OcTreeNode& node) { return detail::ChildArrayAccess::of(node) != nullptr; }

// createNodeChild(parent, index) without the count: the caller adds the nodes it made to the
// tree's counter (add_to_node_count). `parent` has no child at `index`.
inline octomap::OcTreeNode* make_child_node(octomap::OcTreeNode& parent, unsigned index) {
  octomap::AbstractOcTreeNode**& children = detail::ChildArrayAccess::of(parent);
  if (children == nullptr) children = new octomap::AbstractOcTreeNode*[8]();
  auto* child = new octomap::OcTreeNode();
  children[index] = child;
  return child;
}

}  // namespace ort
