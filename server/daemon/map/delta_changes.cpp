#include "daemon/map/delta_changes.h"

#include <algorithm>

#include "octomap_rt/map_delta_t.hpp"

namespace ort::daemon {
namespace {

using Delta = octomap_rt::map_delta_t;

int8_t class_of(float log_odds, float occupancy_thres_log) {
  return log_odds >= occupancy_thres_log ? Delta::CLASS_OCCUPIED : Delta::CLASS_FREE;
}

uint64_t packed_key(const LeafChange& c) {
  uint16_t x, y, z;
  morton_decode(c.morton(), x, y, z);
  return protocol::pack_key(octomap::OcTreeKey(x, y, z));
}

}  // namespace

void append_delta_changes(const LeafChanges& scan, bool exact, float occupancy_thres_log,
                          std::vector<protocol::VoxelChange>& out) {
  if (exact) {
    out.reserve(out.size() + scan.size());
    scan.for_each([&](const LeafChange& c) { out.push_back({packed_key(c), c.after}); });
    return;
  }
  scan.for_each([&](const LeafChange& c) {
    const int8_t now = class_of(c.after, occupancy_thres_log);
    if (c.was_unknown() || class_of(c.before, occupancy_thres_log) != now)
      out.push_back({packed_key(c), static_cast<float>(now)});
  });
}

void keep_newest_per_key(std::vector<protocol::VoxelChange>& set) {
  // After a stable sort by key, the last of each key's run is its newest value.
  std::stable_sort(set.begin(), set.end(),
                   [](const protocol::VoxelChange& a, const protocol::VoxelChange& b) { return a.key < b.key; });
  size_t kept = 0;
  for (size_t i = 0; i < set.size(); ++i)
    if (i + 1 == set.size() || set[i + 1].key != set[i].key) set[kept++] = set[i];
  set.resize(kept);
}

}  // namespace ort::daemon
