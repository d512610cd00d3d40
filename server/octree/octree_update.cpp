#include "octree/octree_update.h"

#include "octree/batched/batched_update.h"

namespace ort {

void apply_updates(octomap::OcTree& tree, std::span<const VoxelUpdate> updates, const OctreeUpdateOptions& opts) {
  switch (opts.mode) {
    case OctreeUpdateMode::kSequential: apply_updates_sequential(tree, updates); return;
    case OctreeUpdateMode::kBatched: apply_updates_batched(tree, updates, opts.threads); return;
  }
}

OctreeStage::OctreeStage(const OctreeUpdateOptions& opts) : opts_(opts) {}
OctreeStage::~OctreeStage() = default;
OctreeStage::OctreeStage(OctreeStage&&) noexcept = default;
OctreeStage& OctreeStage::operator=(OctreeStage&&) noexcept = default;

std::optional<int64_t> OctreeStage::apply(octomap::OcTree& tree, std::span<const VoxelUpdate> updates,
                                          LeafChanges* changes) {
  if (opts_.mode == OctreeUpdateMode::kSequential) {
    apply_updates_sequential(tree, updates, changes);
    return std::nullopt;
  }
  if (!batched_) {
    BatchedUpdateOptions o;
    o.threads = opts_.threads;
    o.helper_nice = opts_.helper_nice;
    batched_ = std::make_unique<BatchedOctreeUpdater>(o);
  }
  return batched_->apply(tree, updates, nullptr, changes);
}

}  // namespace ort
