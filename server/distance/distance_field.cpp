#include "distance/distance_field.h"

#include <algorithm>
#include <cmath>

namespace ort::distance {

float clamped_distance(uint32_t squared, double cell_size, double max_distance) {
  if (squared == kNoObstacle) return static_cast<float>(max_distance);
  return static_cast<float>(std::min(std::sqrt(double(squared)) * cell_size, max_distance));
}

float DistanceField::distance(int64_t i, int64_t j, int64_t k) const {
  return clamped_distance(squared[static_cast<size_t>(index(i, j, k))], cell_size, max_distance);
}

std::array<float, 3> DistanceField::gradient(int64_t i, int64_t j, int64_t k) const {
  const double h = 2 * cell_size;
  return {static_cast<float>((distance(i + 1, j, k) - distance(i - 1, j, k)) / h),
          static_cast<float>((distance(i, j + 1, k) - distance(i, j - 1, k)) / h),
          static_cast<float>((distance(i, j, k + 1) - distance(i, j, k - 1)) / h)};
}

int padding_cells(const DistanceOptions& opt, double resolution) {
  // Obstacles up to max_distance from a box cell or from its neighbour one cell outside.
  return static_cast<int>(std::ceil(opt.max_distance / (resolution * opt.cell_voxels) - 1e-9)) + 1;
}

DistanceField compute_field(const OccupancyGrid& grid, const SquaredEdt& edt, double resolution,
                            const DistanceOptions& opt) {
  DistanceField f;
  f.box = grid.box;
  f.cell_size = resolution * grid.box.cell_voxels;
  f.max_distance = opt.max_distance;
  f.squared.resize(grid.occupied.size());
  edt(grid.occupied, grid.box.dims, f.squared);
  return f;
}

}  // namespace ort::distance
