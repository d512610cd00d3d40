// Shards: several daemons that map one namespace's scans side by side, each owning a fixed set
// of regions (docs/PROTOCOL.md, "Shards"). The rule that names a region's shard is spelled
// here once, on region coordinates, so that the server (which keeps a voxel only where it owns
// the region) and every client (which routes a query to the shard owning its point) agree by
// construction. A region is the subtree at `region_depth`: its coordinates are the voxel key's
// shifted right by 16 - region_depth on each axis (octree/region.h's RegionId packs the same
// three numbers).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "protocol/limits.h"

namespace ort::protocol {

// How a shard set divides the regions (the values travel as int8 in map_info_t and
// server_status_t: SHARD_RULE_*).
enum class ShardRule : int8_t {
  kWhole = 0,  // one daemon, every region (not sharded)
  kHash = 1,   // shard = fmix32(x * 73856093 ^ y * 19349663 ^ z * 83492791) mod count
  kBoxes = 2,  // shard i owns the regions of box i; the boxes tile the key space
};

// The regions' default depth: 8 voxels a side (0.8 m at 0.1 m). Fine enough that one indoor
// scan's voxels spread evenly over the hash rule's shards (coarser regions are too few for one
// scan: the busiest shard gets several times the mean; docs/BENCHMARKS.md, "Shards").
inline constexpr uint32_t kDefaultShardRegionDepth = 13;

struct RegionCoords {
  uint32_t x = 0, y = 0, z = 0;
};

// Regions [min, max) on each axis, in region coordinates.
struct RegionBox {
  uint32_t min[3] = {0, 0, 0}, max[3] = {0, 0, 0};
  bool contains(const RegionCoords& r) const {
    return r.x >= min[0] && r.x < max[0] && r.y >= min[1] && r.y < max[1] && r.z >= min[2] && r.z < max[2];
  }
};

struct ShardSet {
  uint32_t index = 0;  // this daemon's shard, 0 .. count - 1
  uint32_t count = 1;
  ShardRule rule = ShardRule::kWhole;
  uint32_t region_depth = kDefaultShardRegionDepth;  // 1 .. 16
  std::vector<RegionBox> boxes;                      // kBoxes: box i is shard i's, `count` of them
  bool sharded() const { return rule != ShardRule::kWhole; }
};

// The region of a voxel key at `depth`.
inline RegionCoords region_coords(uint32_t depth, uint16_t kx, uint16_t ky, uint16_t kz) {
  const uint32_t s = 16 - depth;
  return RegionCoords{uint32_t(kx) >> s, uint32_t(ky) >> s, uint32_t(kz) >> s};
}

// The hash of the kHash rule (Teschner's spatial hash, then MurmurHash3's 32-bit finaliser).
uint32_t region_hash(const RegionCoords& r);

// The shard owning region `r` (kWhole: 0; kBoxes: the box holding it; count when none does,
// which check_shard_set rules out).
uint32_t shard_of(const ShardSet& set, const RegionCoords& r);

// "" when the set is usable, else why not: count 0 or above kMaxShards, index not below count,
// depth outside 1 .. 16, kWhole with count > 1, kBoxes without one box per shard, an empty box,
// a box past the key space, two boxes sharing a region or a region in no box (the message
// names the boxes and the region).
std::string check_shard_set(const ShardSet& set);

// "i/N" (--shard): 0 <= i < N <= kMaxShards. "" on success, else why not.
std::string parse_shard_index(std::string_view text, uint32_t& index, uint32_t& count);

// The regions (at `depth`, `resolution` metres a voxel) whose min corner lies in [min, max) on
// every axis: --shard-box's metres as a box of regions (limits may be infinite).
RegionBox region_box_of(const double min[3], const double max[3], double resolution, uint32_t depth);

// The namespace of shard `index`'s own channels (map protocol, queries, edits, grid, viewer):
// NS_SHARD<i>, or SHARD<i> without a namespace. Scans and the status stay in NS (protocol/channels.h).
std::string shard_namespace(std::string_view ns, uint32_t index);

// "hash", "boxes" or "whole".
const char* to_string(ShardRule rule);

}  // namespace ort::protocol
