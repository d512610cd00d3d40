// What "the same tree as OctoMap's" means in the octree-stage tests, in one check.
#pragma once

#include <cstdlib>
#include <string>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "octree/batched/batched_update.h"

namespace ort::test {

// The batched stage on `threads` threads with buckets as deep as they go (many small buckets,
// blocks larger than a bucket's node, pruned nodes above them), every batch in parallel.
inline BatchedUpdateOptions deep_buckets(unsigned threads) {
  BatchedUpdateOptions o;
  o.threads = threads;
  o.min_parallel_voxels = 0;
  o.buckets.voxels_per_cell = 1;
  o.buckets.max_cells = 1 << 20;
  o.buckets.min_shift = 1;
  return o;
}

// The production defaults on 7 threads, every batch in parallel (the tests' batches are tiny).
inline BatchedUpdateOptions default_buckets() {
  BatchedUpdateOptions o;
  o.threads = 7;
  o.min_parallel_voxels = 0;
  return o;
}

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
