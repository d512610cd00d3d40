// What "the same tree as OctoMap's" means in the octree-stage tests, in one check.
#pragma once

#include <cstdlib>
#include <string>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

namespace ort::test {

// Node for node (shape, inner values, log-odds), every finest voxel, and the node counter:
// size() equal and equal to the real number of nodes (the batched stage keeps OctoMap's
// counter through node_count.h).
::testing::AssertionResult same_tree(const octomap::OcTree& reference, const octomap::OcTree& batched);

// OCTOMAP_RT_OCTREE_TEST_QUICK set and not "0": the shorter variant of the long cases.
inline bool quick_mode() {
  const char* q = std::getenv("OCTOMAP_RT_OCTREE_TEST_QUICK");
  return q && std::string(q) != "0" && std::string(q) != "";
}

}  // namespace ort::test
