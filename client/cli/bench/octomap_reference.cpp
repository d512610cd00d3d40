#include "cli/bench/octomap_reference.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "cli/bench/process_memory.h"
#include "core/clock.h"

namespace ort::bench {

// The same leaves in the same order, with the same depth and log-odds: the trees are equal
// node for node at the leaves (pruning included). Both iterate depth first in child order.
bool same_leaves(const octomap::OcTree& a, const octomap::OcTree& b) {
  if (a.getNumLeafNodes() != b.getNumLeafNodes()) return false;
  auto ia = a.begin_leafs(), ea = a.end_leafs();
  auto ib = b.begin_leafs(), eb = b.end_leafs();
  for (; ia != ea && ib != eb; ++ia, ++ib) {
    if (ia.getDepth() != ib.getDepth() || ia.getKey() != ib.getKey() || ia->getLogOdds() != ib->getLogOdds())
      return false;
  }
  return ia == ea && ib == eb;
}

// OctoMap itself: insertPointCloud(world points, pose translation, max range, lazy_eval =
// false, discretize = false), scan after scan, as the parity tests build it.
OctomapReference run_octomap(const ScanSet& set, const BenchRow& base, const OctomapRunOptions& a) {
  const double res = base.resolution;
  OctomapReference ref;
  BenchRow& r = ref.row;
  r = base;
  r.backend = "octomap";
  r.device = "CPU (OctoMap 1.9.7 insertPointCloud, 1 thread)";
  r.traversal = "octomap";
  r.octree = "updateNode";
  const size_t warm = std::min<size_t>(a.warmup, set.scans.size());
  {  // warm-up on a throw-away tree, as for the engine runs
    octomap::OcTree scratch(res);
    for (size_t i = 0; i < warm; ++i)
      scratch.insertPointCloud(world_points(set.scans[i]), sensor_origin(set.scans[i]), a.max_range, false, false);
  }
  std::vector<std::pair<double, double>> runs;  // (total, transform)
  for (int rep = 0; rep < a.repeat; ++rep) {
    auto tree = std::make_unique<octomap::OcTree>(res);
    double transform_ms = 0;
    const auto t0 = SteadyClock::now();
    for (const PosedScan& s : set.scans) {
      const auto tt = SteadyClock::now();
      const octomap::Pointcloud world = world_points(s);
      transform_ms += ms_since(tt);
      tree->insertPointCloud(world, sensor_origin(s), a.max_range, false, false);
    }
    runs.push_back({ms_since(t0), transform_ms});
    if (rep + 1 == a.repeat) ref.tree = std::move(tree);
  }
  std::sort(runs.begin(), runs.end());
  r.total_ms = runs[runs.size() / 2].first;
  r.prepare_ms = runs[runs.size() / 2].second;
  // Ray keys + KeySets alone (computeUpdate), so that OctoMap's bar splits like Fig. 6.
  if (a.breakdown) {
    octomap::OcTree keys_only(res);
    for (const PosedScan& s : set.scans) {
      const octomap::Pointcloud world = world_points(s);
      octomap::KeySet free_cells, occupied_cells;
      const auto t = SteadyClock::now();
      keys_only.computeUpdate(world, sensor_origin(s), free_cells, occupied_cells, a.max_range);
      r.shoot_ms += ms_since(t);
    }
  }
  r.octree_ms = std::max(0.0, r.total_ms - r.prepare_ms - r.shoot_ms);
  ref.summary = summarize(*ref.tree);
  r.free_voxels = r.octomap_free = ref.summary.finest_free;
  r.occupied_voxels = r.octomap_occupied = ref.summary.finest_occupied;
  r.counts_equal = r.map_identical = "reference";
  r.tree_bytes = ref.tree->memoryUsage();
  r.rss_bytes = cli::current_rss_bytes();
  r.peak_rss_bytes = cli::peak_rss_bytes();
  r.octomap_total_ms = r.total_ms;
  r.speedup = 1.0;
  r.points_per_s = r.total_ms > 0 ? r.points / (r.total_ms / 1000.0) : 0.0;
  return ref;
}

}  // namespace ort::bench
