// Compares two OcTrees the way the parity tests need: finest-level voxels and their
// log-odds, and (for the octree-stage tests) the whole node structure with inner values.
#pragma once

#include <cstdint>
#include <string>

#include <octomap/OcTree.h>

namespace ort::test {

struct TreeDiff {
  uint64_t differing_voxels = 0;   // finest-level voxels known in one tree only
  uint64_t differing_logodds = 0;  // finest-level voxels known in both with other log-odds
  uint64_t leaves_a = 0, leaves_b = 0;
  std::string first_difference;
  bool maps_equal() const { return differing_voxels == 0 && differing_logodds == 0; }
};

// Leaf-level comparison: every finest voxel, whatever the pruning.
TreeDiff compare_leaves(const octomap::OcTree& a, const octomap::OcTree& b);

// Node-for-node comparison: same nodes (depth, key), same values (inner nodes too), same
// children; i.e. the same pruned shape. Returns "" when identical, else the first difference.
std::string compare_structure(const octomap::OcTree& a, const octomap::OcTree& b);

}  // namespace ort::test
