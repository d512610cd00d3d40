// Loading a map under a memory bound (issue 25): a checked .ot file is split, before OctoMap
// reads it, into the file of a tree that fits a byte budget (every region past the budget a
// childless stand-in holding its value, as eviction leaves it: octree/region_codec.h) and the
// regions cut out, handed to a spill as region bytes. So a map larger than the bound never
// stands whole in memory as a tree: only its file's bytes (5 a node) and the part that fits.
//
// Regions are kept in the file's order (child-index order from the root) until the budget is
// reached; the rest go to the spill. A leaf at or above the region depth is kept as it is.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>

#include "octree/region.h"

namespace ort {

struct MapFileSplit {
  std::string kept;          // the .ot file of the tree that stays (its header's node count set)
  uint64_t kept_nodes = 0;   // nodes in it
  uint64_t kept_memory = 0;  // that tree's memory as OctoMap's memoryUsage() counts it
  uint64_t spilled_regions = 0, spilled_nodes = 0;
};

using RegionSink = std::function<void(RegionId, std::span<const uint8_t>)>;

// `ot` is a whole .ot file that core/file_checks/octree_file_check.h accepted, its node data
// starting at `data_offset`. Keeps regions while the kept tree's memory stays within
// `keep_bytes`; calls `spill(id, region bytes)` for each region cut out (a spill that throws
// ends the split with its exception). Throws std::runtime_error when the data is not one
// whole tree.
MapFileSplit split_map_file(std::string_view ot, size_t data_offset, const RegionGrid& grid, uint64_t keep_bytes,
                            const RegionSink& spill);

}  // namespace ort
