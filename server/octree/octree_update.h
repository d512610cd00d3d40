// CPU stage: applies one scan's voxel list to an octomap::OcTree with OctoMap's sensor
// model (log-odds, clamping, pruning, lazy_eval = false), giving exactly the tree that
// OctoMap's insertPointCloud gives.
#pragma once

#include <span>

#include <octomap/OcTree.h>

#include "engine/voxel_update.h"

namespace ort {

enum class OctreeUpdateMode {
  kSequential,  // one OcTree::updateNode per voxel: OctoMap's own loop, the reference
  kBatched,     // key-ordered batched descent, multi-threaded (octree/batched_update.h)
};

struct OctreeUpdateOptions {
  OctreeUpdateMode mode = OctreeUpdateMode::kSequential;
  unsigned threads = 0;  // batched mode: 0 = hardware threads
};

// Plain updateNode loop: each voxel updated once, occupied or free.
void apply_updates_sequential(octomap::OcTree& tree, std::span<const VoxelUpdate> updates);

void apply_updates(octomap::OcTree& tree, std::span<const VoxelUpdate> updates,
                   const OctreeUpdateOptions& opts);

}  // namespace ort
