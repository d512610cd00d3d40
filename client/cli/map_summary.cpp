#include "cli/map_summary.h"

#include <ostream>

namespace ort {

MapSummary summarize(const octomap::OcTree& tree) {
  MapSummary s;
  const unsigned max_depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const uint64_t finest = uint64_t(1) << (3 * (max_depth - it.getDepth()));
    if (tree.isNodeOccupied(*it)) {
      ++s.stored_occupied;
      s.finest_occupied += finest;
    } else {
      ++s.stored_free;
      s.finest_free += finest;
    }
  }
  s.nodes = tree.size();
  s.memory_bytes = tree.memoryUsage();
  return s;
}

void print_summary(std::ostream& os, const MapSummary& s) {
  os << "  leaves stored:   " << s.stored_free << " free, " << s.stored_occupied << " occupied\n"
     << "  finest level:    " << s.finest_free << " free, " << s.finest_occupied << " occupied\n"
     << "  nodes:           " << s.nodes << " (" << (s.memory_bytes >> 10) << " KiB)\n";
}

}  // namespace ort
