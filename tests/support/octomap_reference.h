// The real thing: maps built by the OctoMap library itself, for parity tests.
#pragma once

#include <memory>

#include <octomap/OcTree.h>

#include "scene/scan_set.h"

namespace ort::test {

// OctoMap's insertPointCloud(world points, origin = pose translation, max_range,
// lazy_eval = false, discretize = false) for every scan, in order.
inline std::unique_ptr<octomap::OcTree> octomap_reference(const ScanSet& set, double resolution, double max_range) {
  auto tree = std::make_unique<octomap::OcTree>(resolution);
  for (const PosedScan& s : set.scans) {
    tree->insertPointCloud(world_points(s), sensor_origin(s), max_range, false, false);
  }
  return tree;
}

}  // namespace ort::test
