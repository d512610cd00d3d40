// The 2D grid of a z band, with octomap_server's projected_map rule: a cell is occupied
// if any finest voxel of its column in the band is occupied, free if any is free and none
// is occupied, unknown otherwise. Cells are cell_voxels x cell_voxels finest voxels,
// aligned to the key grid with a cell boundary at x = 0 and y = 0, so grids of the same
// cell size line up whatever their window.
#pragma once

#include <cstdint>

#include <octomap/OcTree.h>

#include "query/query_types.h"
#include "query/work_budget.h"

namespace ort::query {

struct GridRequest {
  double z_min = 0, z_max = 0;  // metres; the band is coordToKey(z_min) .. coordToKey(z_max)
  int cell_voxels = 1;          // >= 1: cell size = cell_voxels * resolution
  bool window = false;          // false: the map's xy extent (its stored leaves)
  double x_min = 0, y_min = 0, x_max = 0, y_max = 0;
  int64_t max_cells = 16'000'000;  // more: QueryError
};

// Throws QueryError: non-finite or inverted band or window, cell_voxels < 1, too many cells.
// With a budget (one unit per leaf visited, the map's extent included; the cells are
// bounded by max_cells), a walk that runs out returns a partial grid with budget->cut set: not an answer.
Grid2D projected_grid(const octomap::OcTree& tree, const GridRequest& req, WorkBudget* budget = nullptr);

}  // namespace ort::query
