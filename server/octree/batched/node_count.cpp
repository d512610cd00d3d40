#include "octree/batched/node_count.h"

namespace ort {
namespace {

// Never instantiated: only its right to name the protected members of OctoMap's base.
struct NodeCounterAccess : octomap::OcTree {
  static size_t& counter(octomap::OcTree& tree) { return tree.*(&NodeCounterAccess::tree_size); }
  static bool& extent_changed(octomap::OcTree& tree) { return tree.*(&NodeCounterAccess::size_changed); }
};

}  // namespace

void add_to_node_count(octomap::OcTree& tree, int64_t delta) {
  // Modulo 2^64, as the counter itself goes when a counting tree deletes more than it made.
  NodeCounterAccess::counter(tree) += static_cast<size_t>(delta);
  NodeCounterAccess::extent_changed(tree) = true;
}

int64_t take_node_count(octomap::OcTree& counting) {
  size_t& c = NodeCounterAccess::counter(counting);
  const int64_t change = static_cast<int64_t>(c);
  c = 0;
  return change;
}

}  // namespace ort
