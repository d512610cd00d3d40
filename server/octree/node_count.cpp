#include "octree/node_count.h"

namespace ort {

void add_to_node_count(octomap::OcTree& tree, octomap::OcTree& helper, int64_t delta) {
  // Children made for `holder` never join a tree; `holder` must end without a child array
  // (OcTreeDataNode's destructor expects that), which only pruneNode frees publicly.
  octomap::OcTreeNode holder;
  octomap::OcTree& up = delta >= 0 ? tree : helper;    // its createNodeChild counts +1
  octomap::OcTree& down = delta >= 0 ? helper : tree;  // its deleteNodeChild counts -1
  uint64_t remaining = delta >= 0 ? static_cast<uint64_t>(delta) : static_cast<uint64_t>(-(delta + 1)) + 1;

  // Eight at a time: expandNode makes 8 equal leaf children, pruneNode deletes them again
  // together with the child array.
  for (; remaining >= 8; remaining -= 8) {
    up.expandNode(&holder);
    down.pruneNode(&holder);
  }
  for (; remaining > 0; --remaining) {
    up.createNodeChild(&holder, 0);
    down.deleteNodeChild(&holder, 0);
  }
  // Sets the tree's size_changed flag even when delta is 0.
  tree.createNodeChild(&holder, 0);
  tree.deleteNodeChild(&holder, 0);
  // createNodeChild left a child array behind: free it the public way.
  helper.expandNode(&holder);
  helper.pruneNode(&holder);
}

}  // namespace ort
