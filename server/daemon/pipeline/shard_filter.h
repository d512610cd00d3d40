// A shard keeps only the voxels of the regions it owns (protocol/shards/shard_set.h's rule on
// octree/region.h's regions). Rays are walked whole, exactly as OctoMap walks them, before the
// cut, so every voxel a shard keeps has the update the one-daemon map gives it: a shard's map
// is OctoMap's map of the same scans restricted to its regions (docs/PROTOCOL.md, "Shards").
// may_hold() is the engine's ray clip (MapEngine::set_ray_clip): a ray whose walk meets none of
// the shard's regions is not walked at all.
#pragma once

#include <cstdint>

#include "core/voxel_update.h"
#include "engine/map_engine.h"
#include "octree/region.h"
#include "protocol/shards/shard_set.h"

namespace ort::daemon {

class ShardFilter {
 public:
  ShardFilter() = default;  // keeps every voxel
  // `set` must pass protocol::check_shard_set.
  explicit ShardFilter(const protocol::ShardSet& set);
  bool active() const { return set_.sharded(); }
  bool owns(const octomap::OcTreeKey& key) const;
  // Whether the inclusive key box meets a region of this shard (never false when it does; true
  // without looking for a hashed box of more than kMostRegionsLooked regions).
  bool may_hold(const KeyBox& box) const;
  static constexpr uint64_t kMostRegionsLooked = 64;
  // Removes the voxels of other shards' regions, keeping the list's order; returns how many
  // it removed.
  uint64_t keep_owned(VoxelList& voxels) const;
  // The same on a shot scan, its free and occupied counts kept in step.
  void keep_owned(ShotScan& shot) const;
  const protocol::ShardSet& set() const { return set_; }

 private:
  protocol::ShardSet set_;
  RegionGrid grid_;
};

}  // namespace ort::daemon
