// The 2D grid follows octomap_server's projected_map rule cell for cell (occupied if any
// voxel of the cell's column in the z band is occupied, free if any is free and none is
// occupied, else unknown), checked voxel by voxel with OctoMap's search().
#include <gtest/gtest.h>

#include <random>

#include "brute_force.h"
#include "query/box_count.h"
#include "query/projected_grid.h"
#include "query_test_maps.h"

namespace ort::test {
namespace {

using query::VoxelState;

query::KeyBox cell_box(const query::Grid2D& g, int i, int j) {
  query::KeyBox b;
  b.min = octomap::OcTreeKey(std::max(0, g.key_x0 + i * g.cell_voxels), std::max(0, g.key_y0 + j * g.cell_voxels),
                             g.key_z0);
  b.max = octomap::OcTreeKey(std::min(65535, g.key_x0 + (i + 1) * g.cell_voxels - 1),
                             std::min(65535, g.key_y0 + (j + 1) * g.cell_voxels - 1), g.key_z1);
  return b;
}

VoxelState projected(const query::BoxCounts& c) {
  return c.occupied ? VoxelState::kOccupied : c.free ? VoxelState::kFree : VoxelState::kUnknown;
}
// A wrong variant: free wins over occupied (a cell is free when any voxel is free).
VoxelState free_wins(const query::BoxCounts& c) {
  return c.free ? VoxelState::kFree : c.occupied ? VoxelState::kOccupied : VoxelState::kUnknown;
}

TEST(GridQuery, WindowCellsEqualTheRuleOverSearchedVoxels) {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(0, 1);
  for (const NamedMap& m : query_test_maps()) {
    const octomap::OcTree& t = *m.tree;
    const double res = t.getResolution();
    double lo[3], hi[3];
    map_extent(t, 0.5, lo, hi);
    int cells[3] = {0, 0, 0}, mutant_disagrees = 0;
    for (int q = 0; q < 40; ++q) {
      query::GridRequest r;
      r.cell_voxels = std::uniform_int_distribution<int>(1, 5)(rng);
      r.z_min = lo[2] + u(rng) * (hi[2] - lo[2]);
      r.z_max = r.z_min + u(rng) * 20 * res;
      r.window = true;
      r.x_min = lo[0] + u(rng) * (hi[0] - lo[0]);
      r.y_min = lo[1] + u(rng) * (hi[1] - lo[1]);
      r.x_max = r.x_min + u(rng) * 30 * r.cell_voxels * res;
      r.y_max = r.y_min + u(rng) * 30 * r.cell_voxels * res;
      const query::Grid2D g = query::projected_grid(t, r);
      ASSERT_EQ(g.cells.size(), size_t(g.width) * g.height);
      // The window is covered, cells are aligned with a boundary at 0.
      EXPECT_LE(g.origin_x, r.x_min + 1e-9);
      EXPECT_GE(g.origin_x + g.width * g.cell_size, r.x_max - 1e-9);
      EXPECT_NEAR(std::remainder(g.origin_x, g.cell_size), 0.0, 1e-6);
      for (int j = 0; j < g.height; ++j)
        for (int i = 0; i < g.width; ++i) {
          const query::BoxCounts c = brute_counts(t, cell_box(g, i, j));
          ASSERT_EQ(g.at(i, j), projected(c)) << m.name << " cell " << i << "," << j;
          cells[int(g.at(i, j))]++;
          mutant_disagrees += free_wins(c) != g.at(i, j);
        }
    }
    EXPECT_GT(cells[int(VoxelState::kOccupied)], 20) << m.name;
    EXPECT_GT(cells[int(VoxelState::kFree)], 20) << m.name;
    EXPECT_GT(cells[int(VoxelState::kUnknown)], 20) << m.name;
    EXPECT_GT(mutant_disagrees, 0) << m.name << ": the occupied-wins rule is not exercised";
  }
}

TEST(GridQuery, WholeMapGridCoversEveryLeafAndAgreesWithBoxCounts) {
  for (const NamedMap& m : query_test_maps()) {
    const octomap::OcTree& t = *m.tree;
    double lo[3], hi[3];
    map_extent(t, 0, lo, hi);
    query::GridRequest r;
    r.cell_voxels = 4;
    r.z_min = lo[2] + 0.3 * (hi[2] - lo[2]);
    r.z_max = r.z_min + 1.0;
    const query::Grid2D g = query::projected_grid(t, r);
    ASSERT_GT(g.width, 0);
    for (int j = 0; j < g.height; ++j)
      for (int i = 0; i < g.width; ++i)
        ASSERT_EQ(g.at(i, j), projected(query::count_box(t, cell_box(g, i, j)))) << m.name << " " << i << "," << j;
    // Every leaf's xy lies inside the grid.
    EXPECT_LE(g.origin_x, lo[0] + 1e-6);
    EXPECT_LE(g.origin_y, lo[1] + 1e-6);
    EXPECT_GE(g.origin_x + g.width * g.cell_size, hi[0] - 1e-6);
    EXPECT_GE(g.origin_y + g.height * g.cell_size, hi[1] - 1e-6);
  }
}

TEST(GridQuery, RefusesBadRequests) {
  const octomap::OcTree& t = *query_test_maps()[0].tree;
  query::GridRequest r;
  r.z_min = 1, r.z_max = 0;
  EXPECT_THROW(query::projected_grid(t, r), query::QueryError);
  r.z_min = 0, r.z_max = NAN;
  EXPECT_THROW(query::projected_grid(t, r), query::QueryError);
  r.z_max = 1, r.cell_voxels = 0;
  EXPECT_THROW(query::projected_grid(t, r), query::QueryError);
  r.cell_voxels = 1, r.max_cells = 10;
  EXPECT_THROW(query::projected_grid(t, r), query::QueryError);
  octomap::OcTree empty(0.1);
  r.max_cells = 1000;
  const query::Grid2D g = query::projected_grid(empty, r);
  EXPECT_EQ(g.width * g.height, 0);
}

}  // namespace
}  // namespace ort::test
