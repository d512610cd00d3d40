#include "octree/octree_update.h"

namespace ort {

void apply_updates(octomap::OcTree& tree, std::span<const VoxelUpdate> updates,
                   const OctreeUpdateOptions& opts) {
  switch (opts.mode) {
    case OctreeUpdateMode::kSequential:
      apply_updates_sequential(tree, updates);
      return;
    case OctreeUpdateMode::kBatched:
      break;
  }
  throw std::runtime_error("batched octree update is not built yet");
}

}  // namespace ort
