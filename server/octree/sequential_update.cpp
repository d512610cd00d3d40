#include "octree/octree_update.h"

namespace ort {

void update_node_logged(octomap::OcTree& tree, const VoxelUpdate& u, std::vector<LeafChange>* lane) {
  const octomap::OcTreeKey key = u.key();
  if (!lane) {
    tree.updateNode(key, u.occupied(), /*lazy_eval=*/false);
    return;
  }
  // updateNode's returned node may have been pruned away on its way back up: search again.
  const octomap::OcTreeNode* node = tree.search(key);
  const bool was_unknown = node == nullptr;
  const float before = node ? node->getLogOdds() : 0.0f;
  tree.updateNode(key, u.occupied(), /*lazy_eval=*/false);
  const float after = tree.search(key)->getLogOdds();
  log_leaf_change(*lane, morton_code(u.x, u.y, u.z), was_unknown, before, after);
}

void apply_updates_sequential(octomap::OcTree& tree, std::span<const VoxelUpdate> updates, LeafChanges* changes) {
  if (!changes) {
    for (const VoxelUpdate& u : updates) tree.updateNode(u.key(), u.occupied(), /*lazy_eval=*/false);
    return;
  }
  changes->reset(1);
  for (const VoxelUpdate& u : updates) update_node_logged(tree, u, &changes->lane(0));
  changes->close_segment(0, 0);
  changes->finish();
}

}  // namespace ort
