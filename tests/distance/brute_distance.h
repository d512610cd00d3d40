// Distances written from the definition, cell by cell, for the exactness tests: a cell's
// obstacle state from one OctoMap search() per finest voxel in it, and a cell's squared
// distance as the minimum over every obstacle cell within reach, by plain enumeration.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <octomap/OcTree.h>

#include "distance/distance_types.h"

namespace ort::test {

// Obstacle cells of the absolute cells [lo, lo + n) (cell c holds keys c * m .. c * m + m - 1;
// keys outside [0, 2^16) are unknown).
struct BruteObstacles {
  std::array<int64_t, 3> lo{};
  std::array<int64_t, 3> n{};
  std::vector<uint8_t> blocked;
  bool at(int64_t x, int64_t y, int64_t z) const;  // absolute cell; false outside
};
BruteObstacles brute_obstacles(const octomap::OcTree& t, std::array<int64_t, 3> lo, std::array<int64_t, 3> n, int m,
                               distance::UnknownAs unknown);

// Squared distance (cell units) from absolute cell c to the nearest obstacle within `reach`
// cells on every axis, kNoObstacle when none.
uint32_t brute_squared(const BruteObstacles& o, const std::array<int64_t, 3>& c, int reach);

}  // namespace ort::test
