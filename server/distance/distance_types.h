// Plain types of the distance transform (server/distance/): what a client asks (how far to
// look, what unknown space is), the typed refusal, and the hook a device EDT plugs into.
//
// Definitions (docs/PROTOCOL.md, "Distance queries"): a cell is a cube of `cell_voxels`
// finest voxels a side, aligned to multiples of cell_voxels in OctoMap's key space. A cell
// is an obstacle if any finest voxel in it is occupied (or unknown, with kOccupied). The
// distance of a cell is the Euclidean distance from its centre to the nearest obstacle
// cell's centre, clamped at max_distance; it is computed exactly as an integer squared
// distance in cell units, so no rounding of square roots enters the comparison.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>

namespace ort::distance {

enum class UnknownAs : int8_t { kFree = 0, kOccupied = 1 };

// The regions a map owns when it is one shard of a set (docs/PROTOCOL.md, "Shards"): the
// unknown space of other shards' regions is theirs to count, so with UnknownAs::kOccupied a
// shard counts as obstacles only its own unknown space (and what lies outside the key range,
// which every shard counts alike). The obstacles of the set are then the union of its shards',
// and a distance of the set is the smallest of its shards' distances. Empty `owns`: every
// region is this map's.
struct RegionOwnership {
  unsigned region_depth = 16;  // regions are the subtrees at this depth (1..16)
  std::function<bool(uint32_t rx, uint32_t ry, uint32_t rz)> owns;
};

struct DistanceOptions {
  double max_distance = 2.0;  // [m] > 0; distances are clamped here, obstacles this far counted
  int cell_voxels = 1;        // 1 = the map's resolution; else a coarser cell (<= kMaxCellVoxels)
  UnknownAs unknown = UnknownAs::kFree;
  RegionOwnership ownership;  // a shard's regions; empty: the whole map
};

inline constexpr int kMaxCellVoxels = 64;
// Squared distance of a cell with no obstacle anywhere in the grid it was computed on.
inline constexpr uint32_t kNoObstacle = 0xFFFFFFFFu;
// Longest grid axis the EDT takes (squared distances then fit 32 bits with room).
inline constexpr int kMaxGridAxis = 8192;

// A request the map cannot answer as asked (too large, outside the key range, ...).
class DistanceError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// Squared EDT of a dense grid: obstacles (occupied[i] != 0) in, for every cell the squared
// distance in cell units to the nearest obstacle cell (kNoObstacle if there is none) out.
// Index i = x + nx * (y + ny * z). The CPU one is squared_edt (squared_edt.h); the Vulkan
// one is gpu/distance_transform.h. Both are exact, so they agree bit for bit.
struct GridDims {
  int nx = 0, ny = 0, nz = 0;
  int64_t cells() const { return int64_t(nx) * ny * nz; }
};
using SquaredEdt = std::function<void(std::span<const uint8_t> occupied, GridDims dims, std::span<uint32_t> out)>;

}  // namespace ort::distance
