// Scene geometry for the simulated sensors: axis-aligned boxes behind a uniform grid, or a
// dense occupancy grid (for real maps such as geb079.bt), and a ray cast against either.
//
// Deliberately independent of the mapping code: its own vector type, its own double
// arithmetic and its own grid walk, so that a bug in the engine's traversal can never hide
// itself by also shaping the data the engine is measured on.
#pragma once

#include <cstdint>
#include <vector>

namespace ort::scene {

struct Vec3 {
  double x = 0, y = 0, z = 0;
  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};
inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(Vec3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }

struct Box {
  Vec3 lo, hi;
};

// Boxes bucketed into a uniform grid of cells: a ray visits only the boxes of the cells it
// crosses, front to back, and stops at the first cell that holds a hit nearer than its exit.
struct BoxGrid {
  std::vector<Box> boxes;
  Vec3 lo, hi;        // grid bounds (the boxes' bounds, padded)
  double cell = 1.0;  // cell edge length [m]
  int dims[3] = {0, 0, 0};
  std::vector<uint32_t> cell_start;  // CSR: boxes of cell c are box_index[cell_start[c] .. cell_start[c+1])
  std::vector<uint32_t> box_index;
};

// Builds the grid; the cell size is `cell` unless that would give more than ~4M cells.
BoxGrid build_box_grid(std::vector<Box> boxes, double cell = 1.0);

// A dense grid of occupied cubes (a real map rasterised at its resolution).
struct OccupancyGrid {
  Vec3 lo;             // corner of cell (0,0,0)
  double voxel = 0.1;  // cube edge length [m]
  int dims[3] = {0, 0, 0};
  std::vector<uint64_t> bits;  // 1 bit a cell, x fastest
  bool occupied(int x, int y, int z) const {
    const uint64_t i = (uint64_t(z) * dims[1] + y) * dims[0] + x;
    return (bits[i >> 6] >> (i & 63)) & 1u;
  }
  void set(int x, int y, int z) {
    const uint64_t i = (uint64_t(z) * dims[1] + y) * dims[0] + x;
    bits[i >> 6] |= uint64_t(1) << (i & 63);
  }
};

// What a sensor looks at: boxes, or an occupancy grid.
struct Scene {
  BoxGrid boxes;
  OccupancyGrid grid;
  bool use_grid = false;
};

// Distance along the unit direction `d` from `o` to the first surface, or a value > max_t
// when nothing is hit within max_t.
double cast_ray(const Scene& scene, const Vec3& o, const Vec3& d, double max_t);
double cast_ray(const BoxGrid& grid, const Vec3& o, const Vec3& d, double max_t);
double cast_ray(const OccupancyGrid& grid, const Vec3& o, const Vec3& d, double max_t);

// True when the point lies inside some box (or occupied cell): used to keep sensor poses
// out of walls and furniture.
bool inside_solid(const Scene& scene, const Vec3& p, double margin);

}  // namespace ort::scene
