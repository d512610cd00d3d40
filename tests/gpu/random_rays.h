// Random scans for the traversal tests: few rays per scan, so that each ray's voxel set is
// checkable, drawn from the cases where a ray walk goes wrong first: axis-aligned rays, rays
// in voxel faces, through edges and corners (coordinates on grid multiples), zero-length and
// sub-voxel rays, negative coordinates, the +-32768-key edge, rays cut at max range.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <octomap/octomap_types.h>

namespace ort::test {

struct RandomScan {
  std::string kind;  // which generator made it (for messages and coverage counts)
  octomap::point3d origin;
  std::vector<octomap::point3d> points;
  double max_range = -1.0;
  double resolution = 0.1;
};

// The seed: $OCTOMAP_RT_TEST_SEED if set, else a fixed default.
uint64_t test_seed();

// One scan of 1..8 rays of a randomly chosen kind.
RandomScan random_scan(std::mt19937_64& rng);

}  // namespace ort::test
