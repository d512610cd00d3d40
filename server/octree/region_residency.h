// The memory bound's bookkeeping (issue 25): which regions are in memory, which were spilled
// (octree/region_codec.h) and when each was last touched. Past the bound, the regions least
// recently touched are spilled; touching a spilled region brings it back first.
//
// Why a touched region's seven siblings come back with it: a spilled region's stand-in is a
// childless node, so an update that prunes the parent (its eight children leaves of one
// value) could swallow a stand-in where the map without eviction keeps a subtree. With all
// eight children of a touched region's parent real, every prune an update makes is the one
// it makes without eviction (stand-ins sit only at the region depth, and a node above with a
// stand-in below it has children, so it is never pruned).
#pragma once

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include <octomap/OcTree.h>

#include "core/voxel_update.h"
#include "octree/region.h"

namespace ort {

// Where spilled regions go (daemon/persistence/region_store.h on disk; tests keep them in
// memory). put() must hold the bytes durably before it returns, or throw.
class RegionSpill {
 public:
  virtual ~RegionSpill() = default;
  virtual void put(RegionId id, std::span<const uint8_t> bytes) = 0;
  virtual std::vector<uint8_t> get(RegionId id) = 0;
  virtual void erase(RegionId id) = 0;
};

struct ResidencyStats {
  uint64_t evictions = 0, restores = 0;
  uint64_t evicted_regions = 0, evicted_bytes = 0;  // now
};

class RegionResidency {
 public:
  RegionResidency(const RegionGrid& grid, RegionSpill& spill, uint64_t max_bytes);

  // The regions named are about to be read or changed: each becomes the most recently
  // touched, and each spilled one (with its parent's other children) is brought back.
  void touch(octomap::OcTree& tree, std::span<const RegionId> ids);
  // touch() for the regions of a voxel list's keys.
  void touch_voxels(octomap::OcTree& tree, std::span<const VoxelUpdate> voxels);
  // Spills the least recently touched regions until the tree's memory (OctoMap's
  // memoryUsage()) is within the bound. Returns the regions spilled.
  size_t enforce(octomap::OcTree& tree);
  // Brings every spilled region back (a whole-map save or snapshot without the bound).
  void restore_all(octomap::OcTree& tree);
  bool spilled(RegionId id) const { return spilled_.count(id) != 0; }
  ResidencyStats stats() const;
  const RegionGrid& grid() const { return grid_; }

 private:
  void restore(octomap::OcTree& tree, RegionId id);

  RegionGrid grid_;
  RegionSpill& spill_;
  uint64_t max_bytes_;
  uint64_t tick_ = 0;
  std::unordered_map<RegionId, uint64_t> last_touch_;
  std::unordered_map<RegionId, uint64_t> spilled_;  // id -> bytes spilled
  ResidencyStats stats_;
};

}  // namespace ort
