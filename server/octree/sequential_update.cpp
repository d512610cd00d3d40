#include "octree/octree_update.h"

namespace ort {

void apply_updates_sequential(octomap::OcTree& tree, std::span<const VoxelUpdate> updates) {
  for (const VoxelUpdate& u : updates) tree.updateNode(u.key(), u.occupied(), /*lazy_eval=*/false);
}

}  // namespace ort
