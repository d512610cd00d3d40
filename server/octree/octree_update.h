// CPU stage: applies one scan's voxel list to an octomap::OcTree with OctoMap's sensor
// model (log-odds, clamping, pruning, lazy_eval = false), giving exactly the tree that
// OctoMap's insertPointCloud gives.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include <octomap/OcTree.h>

#include "core/voxel_update.h"
#include "octree/leaf_changes.h"

namespace ort {

enum class OctreeUpdateMode {
  kSequential,  // one OcTree::updateNode per voxel: OctoMap's own loop, the reference
  kBatched,     // key-ordered batched descent, multi-threaded (octree/batched/batched_update.h)
};

struct OctreeUpdateOptions {
  OctreeUpdateMode mode = OctreeUpdateMode::kBatched;
  unsigned threads = 0;  // batched mode: 0 = hardware threads
  // Batched mode: how much the threads other than the caller lower their priority
  // (worker_pool.h); 19 for an update that should take only idle cores beside another (the
  // read replica's).
  int helper_nice = 0;
};

// Plain updateNode loop: each voxel updated once, occupied or free. With `changes`: reset,
// then every update that changed its leaf, found by a search before and after it (one lane,
// one segment; leaf_changes.h).
void apply_updates_sequential(octomap::OcTree& tree, std::span<const VoxelUpdate> updates,
                              LeafChanges* changes = nullptr);

// One updateNode; with `lane`, its change (if any) appended to it.
void update_node_logged(octomap::OcTree& tree, const VoxelUpdate& u, std::vector<LeafChange>* lane);

// One-off: the batched mode starts its threads for this call only (see OctreeStage).
void apply_updates(octomap::OcTree& tree, std::span<const VoxelUpdate> updates, const OctreeUpdateOptions& opts);

class BatchedOctreeUpdater;

// The octree stage as the engine keeps it: in batched mode the updater, its threads and
// buffers are made on first use and kept from scan to scan. One apply() at a time.
class OctreeStage {
 public:
  explicit OctreeStage(const OctreeUpdateOptions& opts);
  ~OctreeStage();
  OctreeStage(OctreeStage&&) noexcept;
  OctreeStage& operator=(OctreeStage&&) noexcept;

  // With `changes`: reset and filled with what the update changed (leaf_changes.h).
  // Returns the change of the tree's leaf count (getNumLeafNodes()) without a walk; none
  // where the stage cannot say (sequential mode, change detection on).
  std::optional<int64_t> apply(octomap::OcTree& tree, std::span<const VoxelUpdate> updates,
                               LeafChanges* changes = nullptr);

 private:
  OctreeUpdateOptions opts_;
  std::unique_ptr<BatchedOctreeUpdater> batched_;
};

}  // namespace ort
