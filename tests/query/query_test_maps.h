// The real maps the query tests ask: loaded or built once per test program.
#pragma once

#include <random>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

namespace ort::test {

struct NamedMap {
  std::string name;
  const octomap::OcTree* tree;
};

// geb079.bt (OctoMap's FR-079 corridor map, read with readBinary) and the 3dtk scans and
// OctoMap's scan_dat inserted by OctoMap's insertPointCloud (0.2 m and 0.1 m).
const std::vector<NamedMap>& query_test_maps();

// A random point of the kinds the tests need: inside the map's extent, outside it (also
// beyond the key range), on voxel boundaries (exact multiples of the resolution).
octomap::point3d random_point(const octomap::OcTree& t, std::mt19937& rng);
// The map's metric extent (its stored leaves), widened by `margin` metres.
void map_extent(const octomap::OcTree& t, double margin, double lo[3], double hi[3]);

}  // namespace ort::test
