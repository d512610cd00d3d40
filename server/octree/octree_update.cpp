#include "octree/octree_update.h"

#include "octree/batched_update.h"

namespace ort {

void apply_updates(octomap::OcTree& tree, std::span<const VoxelUpdate> updates,
                   const OctreeUpdateOptions& opts) {
  switch (opts.mode) {
    case OctreeUpdateMode::kSequential:
      apply_updates_sequential(tree, updates);
      return;
    case OctreeUpdateMode::kBatched:
      apply_updates_batched(tree, updates, opts.threads);
      return;
  }
}

}  // namespace ort
