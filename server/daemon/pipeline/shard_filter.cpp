#include "daemon/pipeline/shard_filter.h"

#include <algorithm>
#include <stdexcept>

namespace ort::daemon {

ShardFilter::ShardFilter(const protocol::ShardSet& set) : set_(set), grid_(region_grid(set.region_depth)) {
  if (const std::string why = protocol::check_shard_set(set); !why.empty()) throw std::invalid_argument(why);
}

bool ShardFilter::owns(const octomap::OcTreeKey& key) const {
  if (!active()) return true;
  const RegionId id = region_of(grid_, key);
  const protocol::RegionCoords r{uint32_t(id & 0xffff), uint32_t(id >> 16 & 0xffff), uint32_t(id >> 32 & 0xffff)};
  return protocol::shard_of(set_, r) == set_.index;
}

uint64_t ShardFilter::keep_owned(VoxelList& voxels) const {
  if (!active()) return 0;
  const size_t before = voxels.size();
  voxels.erase(std::remove_if(voxels.begin(), voxels.end(), [&](const VoxelUpdate& v) { return !owns(v.key()); }),
               voxels.end());
  return before - voxels.size();
}

void ShardFilter::keep_owned(ShotScan& shot) const {
  if (!active() || keep_owned(shot.voxels) == 0) return;
  shot.occupied_voxels = static_cast<uint64_t>(
      std::count_if(shot.voxels.begin(), shot.voxels.end(), [](const VoxelUpdate& v) { return v.occupied(); }));
  shot.free_voxels = shot.voxels.size() - shot.occupied_voxels;
}

}  // namespace ort::daemon
