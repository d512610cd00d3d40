// A region spill kept in memory (tests of the memory bound: what eviction writes and restores read,
// without a store on disk).
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <vector>

#include "octree/region_residency.h"

namespace ort::test {

class MemorySpill : public RegionSpill {
 public:
  void put(RegionId id, std::span<const uint8_t> b) override { regions[id].assign(b.begin(), b.end()); }
  std::vector<uint8_t> get(RegionId id) override { return regions.at(id); }
  void erase(RegionId id) override { regions.erase(id); }
  std::map<RegionId, std::vector<uint8_t>> regions;
};

}  // namespace ort::test
