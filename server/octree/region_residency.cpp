#include "octree/region_residency.h"

#include <algorithm>
#include <unordered_set>

#include "octree/region_codec.h"

namespace ort {

RegionResidency::RegionResidency(const RegionGrid& grid, RegionSpill& spill, uint64_t max_bytes)
    : grid_(grid), spill_(spill), max_bytes_(max_bytes) {}

void RegionResidency::restore(octomap::OcTree& tree, RegionId id) {
  auto it = spilled_.find(id);
  if (it == spilled_.end()) return;
  const std::vector<uint8_t> bytes = spill_.get(id);
  restore_region(tree, grid_, id, bytes);
  stats_.evicted_bytes -= it->second;
  spilled_.erase(it);
  spill_.erase(id);
  stats_.restores++;
}

void RegionResidency::touch(octomap::OcTree& tree, std::span<const RegionId> ids) {
  ++tick_;
  for (RegionId id : ids) {
    last_touch_[id] = tick_;
    if (spilled_.empty()) continue;
    // The region and its parent's other children (region_residency.h says why).
    const octomap::OcTreeKey k = region_min_key(grid_, id);
    const unsigned side = grid_.side_keys();
    for (unsigned i = 0; i < 8; ++i) {
      octomap::OcTreeKey s = k;
      for (unsigned a = 0; a < 3; ++a) {
        const unsigned parent_min = k[a] & ~(2 * side - 1);
        s[a] = static_cast<uint16_t>(parent_min + ((i >> a) & 1) * side);
      }
      restore(tree, region_of(grid_, s));
    }
  }
}

void RegionResidency::touch_voxels(octomap::OcTree& tree, std::span<const VoxelUpdate> voxels) {
  std::vector<RegionId> ids;
  RegionId last = ~RegionId(0);
  for (const VoxelUpdate& v : voxels) {
    const RegionId id = region_of(grid_, v.key());
    if (id != last) ids.push_back(id);
    last = id;
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  touch(tree, ids);
}

size_t RegionResidency::enforce(octomap::OcTree& tree) {
  uint64_t bytes = tree.memoryUsage();
  if (bytes <= max_bytes_) return 0;
  struct Candidate {
    uint64_t touched;
    RegionId id;
  };
  std::vector<Candidate> candidates;
  for_each_region(tree, grid_, [&](RegionId id, const RegionNode& r) {
    if (r.depth != grid_.depth || !tree.nodeHasChildren(r.node)) return;  // coarse leaves, stand-ins
    auto it = last_touch_.find(id);
    candidates.push_back({it == last_touch_.end() ? 0 : it->second, id});
  });
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.touched != b.touched ? a.touched < b.touched : a.id < b.id;
  });
  const uint64_t per_node = tree.size() ? bytes / tree.size() : 1;
  size_t n = 0;
  for (const Candidate& c : candidates) {
    if (bytes <= max_bytes_) break;
    const std::vector<uint8_t> encoded = encode_region(tree, grid_, c.id);
    spill_.put(c.id, encoded);  // durable before the nodes go
    const uint64_t freed = strip_region(tree, grid_, c.id);
    spilled_[c.id] = encoded.size();
    stats_.evicted_bytes += encoded.size();
    stats_.evictions++;
    bytes -= std::min(bytes, freed * per_node);
    ++n;
  }
  return n;
}

void RegionResidency::restore_all(octomap::OcTree& tree) {
  std::vector<RegionId> ids;
  for (const auto& [id, b] : spilled_) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  for (RegionId id : ids) restore(tree, id);
}

ResidencyStats RegionResidency::stats() const {
  ResidencyStats s = stats_;
  s.evicted_regions = spilled_.size();
  return s;
}

}  // namespace ort
