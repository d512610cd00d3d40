// A computed distance field: the squared distances of a padded grid of cells, and what is
// read from it: the clamped distance of a cell in metres, and its gradient.
//
// Gradient: central differences of the clamped distance field, per axis
// (D(c + e) - D(c - e)) / (2 * cell size), in metres per metre; zero where both neighbours
// are at the clamp (far from every obstacle), and pointing away from the nearest obstacle.
// Cells one step outside a requested box are in the padded grid (padding_cells), so the
// gradient at a box's edge uses exact neighbours too.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "distance/distance_types.h"
#include "distance/occupancy_grid.h"

namespace ort::distance {

struct DistanceField {
  CellBox box;
  std::vector<uint32_t> squared;  // per cell of box, cell units; kNoObstacle: none in the grid
  double cell_size = 0;           // [m]
  double max_distance = 0;        // [m]

  int64_t index(int64_t i, int64_t j, int64_t k) const { return (k * box.dims.ny + j) * box.dims.nx + i; }
  // Clamped distance [m] of cell (i, j, k) of the grid.
  float distance(int64_t i, int64_t j, int64_t k) const;
  // Needs 1 <= i <= nx - 2 (and so on): cells inside the grid's outermost layer.
  std::array<float, 3> gradient(int64_t i, int64_t j, int64_t k) const;
};

// Cells of padding that make every cell of a box (and its neighbours) exact up to max_distance.
int padding_cells(const DistanceOptions& opt, double resolution);
// The clamped distance [m] of a squared cell distance: min(sqrt(sq) * cell_size, max).
float clamped_distance(uint32_t squared, double cell_size, double max_distance);

// Runs the EDT on the grid read from the map.
DistanceField compute_field(const OccupancyGrid& grid, const SquaredEdt& edt, double resolution,
                            const DistanceOptions& opt);

}  // namespace ort::distance
