// Plain answers of the map queries (server/query/): what a point, a ray, a box or a grid
// cell of an octomap::OcTree holds, by OctoMap's own rules. No LCM, no daemon: the daemon
// and the client translate these to and from messages.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <octomap/OcTreeKey.h>
#include <octomap/octomap_types.h>

namespace ort::query {

// A voxel's (or a node's, or a grid cell's) state. The numbers are the wire's OCC_* values.
enum class VoxelState : int8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };
const char* to_string(VoxelState s);

// A query the map cannot answer as asked (non-finite input, a depth the tree does not have,
// a box with min > max, a grid too large). The message says which and why.
class QueryError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

struct PointAnswer {
  VoxelState state = VoxelState::kUnknown;
  float probability = -1.0f;  // the node's occupancy probability; -1 where unknown
};

struct RayAnswer {
  bool hit = false;                             // what OcTree::castRay returned
  octomap::point3d end;                         // what OcTree::castRay wrote into `end`
  VoxelState end_state = VoxelState::kUnknown;  // the end voxel's state (search(end))
};

// Finest-level voxel counts of a key box. occupied + free + unknown = the box's voxels.
struct BoxCounts {
  int64_t occupied = 0, free = 0, unknown = 0;
  bool any_occupied() const { return occupied > 0; }
};

// A node returned by region extraction: a cube of 2^(16 - depth) finest voxels a side.
struct RegionVoxel {
  octomap::OcTreeKey lo{0, 0, 0};  // the cube's lowest finest-level key
  uint8_t depth = 16;              // 1 .. tree depth
  VoxelState state = VoxelState::kFree;
  octomap::point3d center;  // keyToCoord of the node (OctoMap's iterator coordinate)
};

// A 2D occupancy grid in the map's xy plane: cells of `cell_voxels` finest voxels a side.
// Cell (i, j) covers x keys [key_x0 + i*m, key_x0 + (i+1)*m - 1] (m = cell_voxels), the same
// for y, and the key band [key_z0, key_z1] in z. Row j holds cells (0..width-1, j).
struct Grid2D {
  int key_x0 = 0, key_y0 = 0;  // lowest key of cell (0, 0) (may be < 0 at the map's edge)
  int key_z0 = 0, key_z1 = 0;  // the z band, inclusive
  int cell_voxels = 1;
  double cell_size = 0;               // metres: cell_voxels * resolution
  double origin_x = 0, origin_y = 0;  // metres: the min corner of cell (0, 0)
  int width = 0, height = 0;
  std::vector<VoxelState> cells;  // width * height, row-major
  VoxelState at(int i, int j) const { return cells[static_cast<size_t>(j) * width + i]; }
};

}  // namespace ort::query
