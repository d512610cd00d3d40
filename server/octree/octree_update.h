// CPU stage: applies one scan's voxel list to an octomap::OcTree with OctoMap's sensor
// model (log-odds, clamping, pruning, lazy_eval = false), giving exactly the tree that
// OctoMap's insertPointCloud gives.
#pragma once

#include <memory>
#include <span>

#include <octomap/OcTree.h>

#include "core/voxel_update.h"

namespace ort {

enum class OctreeUpdateMode {
  kSequential,  // one OcTree::updateNode per voxel: OctoMap's own loop, the reference
  kBatched,     // key-ordered batched descent, multi-threaded (octree/batched_update.h)
};

struct OctreeUpdateOptions {
  OctreeUpdateMode mode = OctreeUpdateMode::kBatched;
  unsigned threads = 0;  // batched mode: 0 = hardware threads
};

// Plain updateNode loop: each voxel updated once, occupied or free.
void apply_updates_sequential(octomap::OcTree& tree, std::span<const VoxelUpdate> updates);

// One-off: the batched mode starts its threads for this call only (see OctreeStage).
void apply_updates(octomap::OcTree& tree, std::span<const VoxelUpdate> updates,
                   const OctreeUpdateOptions& opts);

class BatchedOctreeUpdater;

// The octree stage as the engine keeps it: in batched mode the updater, its threads and
// buffers are made on first use and kept from scan to scan. One apply() at a time.
class OctreeStage {
 public:
  explicit OctreeStage(const OctreeUpdateOptions& opts);
  ~OctreeStage();
  OctreeStage(OctreeStage&&) noexcept;
  OctreeStage& operator=(OctreeStage&&) noexcept;

  void apply(octomap::OcTree& tree, std::span<const VoxelUpdate> updates);

 private:
  OctreeUpdateOptions opts_;
  std::unique_ptr<BatchedOctreeUpdater> batched_;
};

}  // namespace ort
