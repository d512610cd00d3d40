// The reference every `octomap-rt bench` row is measured against: OctoMap's own
// insertPointCloud on the same scans in the same process, and the leaf-by-leaf equality check.
#pragma once

#include <memory>

#include <octomap/OcTree.h>

#include "cli/bench/bench_results.h"
#include "cli/map_summary.h"
#include "scene/scan_set.h"

namespace ort::bench {

struct OctomapRunOptions {
  int warmup = 1;           // scans inserted into a throw-away tree first
  int repeat = 1;           // timed runs; the median is reported
  double max_range = -1.0;  // OctoMap's maxrange (<= 0: none)
  bool breakdown = true;    // also time computeUpdate alone, to split OctoMap's bar by stage
};

struct OctomapReference {
  BenchRow row;
  std::unique_ptr<octomap::OcTree> tree;
  MapSummary summary;
};

OctomapReference run_octomap(const ScanSet& set, const BenchRow& base, const OctomapRunOptions& options);

// The same leaves in the same order, with the same depth and log-odds.
bool same_leaves(const octomap::OcTree& a, const octomap::OcTree& b);

}  // namespace ort::bench
