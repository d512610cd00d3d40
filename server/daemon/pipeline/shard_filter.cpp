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

bool ShardFilter::may_hold(const KeyBox& box) const {
  if (!active()) return true;
  if (box.empty()) return false;
  const uint32_t s = 16 - set_.region_depth;
  uint32_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a) lo[a] = uint32_t(box.lo[a]) >> s, hi[a] = uint32_t(box.hi[a]) >> s;
  if (set_.rule == protocol::ShardRule::kBoxes) {  // regions [min, max) of its box
    const protocol::RegionBox& b = set_.boxes[set_.index];
    for (int a = 0; a < 3; ++a)
      if (hi[a] < b.min[a] || lo[a] >= b.max[a]) return false;
    return true;
  }
  uint64_t regions = 1;
  for (int a = 0; a < 3; ++a) regions *= hi[a] - lo[a] + 1;
  if (regions > kMostRegionsLooked) return true;
  for (uint32_t x = lo[0]; x <= hi[0]; ++x)
    for (uint32_t y = lo[1]; y <= hi[1]; ++y)
      for (uint32_t z = lo[2]; z <= hi[2]; ++z)
        if (protocol::shard_of(set_, protocol::RegionCoords{x, y, z}) == set_.index) return true;
  return false;
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
