// One voxel's consistent state for one scan, as the ray-shooting stage hands it to the
// octree stage. The layout is what the GPU compaction shader writes (two uint32 words:
// x | y << 16, z | state << 16), so a readback buffer is a VoxelUpdate array as is.
#pragma once

#include <cstddef>  // OctoMap 1.9.7's OcTreeKey.h needs size_t and uint8_t declared first
#include <cstdint>
#include <vector>

#include <octomap/OcTreeKey.h>

namespace ort {

// Paper Fig. 5: two bits a voxel, bit 0 occupied, bit 1 free; 11 resolves to occupied.
enum VoxelStateBits : uint32_t {
  kStateOccupied = 1u,
  kStateFree = 2u,
};

struct VoxelUpdate {
  uint16_t x, y, z;
  uint16_t state;  // kStateOccupied or kStateFree, already resolved (occupied wins)

  octomap::OcTreeKey key() const { return octomap::OcTreeKey(x, y, z); }
  bool occupied() const { return state == kStateOccupied; }
};
static_assert(sizeof(VoxelUpdate) == 8, "VoxelUpdate must match the GPU output layout");

// The voxels one scan updates: each key at most once.
using VoxelList = std::vector<VoxelUpdate>;

inline VoxelUpdate make_update(const octomap::OcTreeKey& k, bool occupied) {
  return VoxelUpdate{k[0], k[1], k[2], static_cast<uint16_t>(occupied ? kStateOccupied : kStateFree)};
}

}  // namespace ort
