// The same dense box field computed in this process, without the daemon, by octomap-rt's
// library (the grid read, then the EDT on CPU threads and, where there is one, the Vulkan
// device) and by OctoMap's own DynamicEDTOctomap (libdynamicedt3d-dev) given our padded grid
// as its box: the ratio of their times on the same map, box and clamp, in the same run.
#pragma once

#include <cstdint>
#include <string>

#include <octomap/OcTree.h>

#include "distance/distance_types.h"

namespace ort::bench {

struct ReferenceTimes {
  int64_t box_cells = 0, padded_cells = 0;
  double read_ms = 0;     // the obstacle grid out of the octree (under the map lock in the daemon)
  double cpu_edt_ms = 0;  // answer_box on CPU threads: the EDT, the clamp, the box cut out
  int cpu_threads = 0;
  double vulkan_edt_ms = -1;  // the same with the Vulkan EDT (-1: no device or not asked)
  std::string vulkan_device;
  double dynamic_edt_ms = -1;  // DynamicEDTOctomap's constructor + update() (-1: not built with it)
  // Cells of the box where DynamicEDTOctomap's squared distance differs from ours below our
  // clamp (their definitions agree there: tests/distance/dynamic_edt_test.cpp): expected 0.
  int64_t dynamic_edt_differ = -1;
  // Of those, the cells where a brute-force search of the padded grid's obstacles gives our
  // value, and where DynamicEDTOctomap's is the larger; the first few as "(i,j,k) ours theirs
  // brute" (squared cells).
  int64_t differ_ours_brute = -1, differ_theirs_larger = -1;
  std::string differ_examples;
};

// Medians over `reps` runs (after one untimed run of each). `tree` is copied for
// DynamicEDTOctomap, which turns on the tree's change detection.
ReferenceTimes time_reference(const octomap::OcTree& tree, const double lo[3], const double hi[3],
                              const distance::DistanceOptions& opt, int threads, int reps, bool vulkan);

}  // namespace ort::bench
