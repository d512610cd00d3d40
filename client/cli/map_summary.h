// Leaf counts of an OcTree, as stored (pruned) and at the finest level.
#pragma once

#include <cstdint>
#include <iosfwd>

#include <octomap/OcTree.h>

namespace ort {

struct MapSummary {
  uint64_t stored_free = 0, stored_occupied = 0;  // leaves as stored (pruned)
  uint64_t finest_free = 0, finest_occupied = 0;  // voxels at the finest level
  uint64_t nodes = 0;
  uint64_t memory_bytes = 0;
};

MapSummary summarize(const octomap::OcTree& tree);
void print_summary(std::ostream& os, const MapSummary& s);

}  // namespace ort
