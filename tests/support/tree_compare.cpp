#include "support/tree_compare.h"

#include <sstream>

namespace ort::test {
namespace {

// Checks every leaf of `from` against the node of `to` that contains its key. A voxel that
// differs lies in one leaf of each tree; the check from the side with the smaller leaf
// finds it, so running this both ways covers every finest voxel.
void one_way(const octomap::OcTree& from, const octomap::OcTree& to, bool count_logodds, TreeDiff& d, uint64_t& leaves,
             const char* from_name) {
  const unsigned max_depth = from.getTreeDepth();
  for (auto it = from.begin_leafs(), end = from.end_leafs(); it != end; ++it) {
    ++leaves;
    const octomap::OcTreeKey key = it.getKey();
    const octomap::OcTreeNode* other = to.search(key);
    // Only count this leaf's voxels when it is at least as fine as the other tree's node.
    unsigned other_depth = 0;
    if (other) {
      // depth of the node search() found: walk down from the root.
      const octomap::OcTreeNode* n = to.getRoot();
      unsigned depth = 0;
      while (n != other && n && to.nodeHasChildren(n)) {
        const unsigned pos = octomap::computeChildIdx(key, max_depth - 1 - depth);
        if (!to.nodeChildExists(n, pos)) break;
        n = to.getNodeChild(n, pos);
        ++depth;
      }
      other_depth = depth;
    }
    const uint64_t voxels = uint64_t(1) << (3 * (max_depth - it.getDepth()));
    if (!other) {
      d.differing_voxels += voxels;
      if (d.first_difference.empty()) {
        std::ostringstream os;
        os << "voxel " << key[0] << "," << key[1] << "," << key[2] << " (depth " << it.getDepth() << ") only in tree "
           << from_name;
        d.first_difference = os.str();
      }
      continue;
    }
    if (count_logodds ? other_depth <= it.getDepth() : other_depth < it.getDepth()) {
      if (other->getLogOdds() != it->getLogOdds()) {
        d.differing_logodds += voxels;
        if (d.first_difference.empty()) {
          std::ostringstream os;
          os << "voxel " << key[0] << "," << key[1] << "," << key[2] << ": log-odds " << it->getLogOdds() << " in "
             << from_name << " vs " << other->getLogOdds();
          d.first_difference = os.str();
        }
      }
    }
  }
}

}  // namespace

TreeDiff compare_leaves(const octomap::OcTree& a, const octomap::OcTree& b) {
  TreeDiff d;
  if (a.getResolution() != b.getResolution()) {
    d.first_difference = "resolutions differ";
    d.differing_voxels = 1;
    return d;
  }
  one_way(a, b, /*count_logodds=*/true, d, d.leaves_a, "A");
  one_way(b, a, /*count_logodds=*/false, d, d.leaves_b, "B");  // equal depths counted once
  return d;
}

std::string compare_structure(const octomap::OcTree& a, const octomap::OcTree& b) {
  if (a.size() != b.size()) {
    std::ostringstream os;
    os << "node counts differ: " << a.size() << " vs " << b.size();
    return os.str();
  }
  auto ia = a.begin_tree(), ea = a.end_tree();
  auto ib = b.begin_tree(), eb = b.end_tree();
  for (; ia != ea && ib != eb; ++ia, ++ib) {
    if (ia.getDepth() != ib.getDepth() || !(ia.getKey() == ib.getKey()) || ia->getLogOdds() != ib->getLogOdds() ||
        a.nodeHasChildren(&*ia) != b.nodeHasChildren(&*ib)) {
      std::ostringstream os;
      os << "node at depth " << ia.getDepth() << " key " << ia.getKey()[0] << "," << ia.getKey()[1] << ","
         << ia.getKey()[2] << " value " << ia->getLogOdds() << (a.nodeHasChildren(&*ia) ? " inner" : " leaf")
         << " vs depth " << ib.getDepth() << " key " << ib.getKey()[0] << "," << ib.getKey()[1] << "," << ib.getKey()[2]
         << " value " << ib->getLogOdds() << (b.nodeHasChildren(&*ib) ? " inner" : " leaf");
      return os.str();
    }
  }
  if ((ia == ea) != (ib == eb)) return "iteration lengths differ";
  return "";
}

}  // namespace ort::test
