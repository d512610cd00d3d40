// Shard maps of the real 3DTK scans for the tests of queries across shards (issues 26, 27): the
// one daemon's map, and the same scans mapped by 3 hashed shards with small regions (depth 12:
// many borders near every query) and by 2 box shards cut at y = 0, each shard keeping its own
// regions' voxels as the daemon's shard filter does.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "daemon/pipeline/shard_filter.h"
#include "engine/map_engine.h"
#include "protocol/shards/shard_set.h"
#include "scene/scan_set.h"
#include "server/scan_fixtures.h"
#include "support/test_data.h"

namespace ort::test {

struct ShardMaps {
  std::string what;
  std::vector<protocol::ShardSet> sets;
  std::vector<std::unique_ptr<octomap::OcTree>> trees;  // by shard index
};

struct ShardedScans {
  std::unique_ptr<ScanSet> scans;
  std::unique_ptr<octomap::OcTree> whole;  // the one daemon's map
  std::vector<ShardMaps> sharded;          // the hashed set, the box set
};

// nullptr when the data set is not there.
inline std::unique_ptr<ShardedScans> sharded_3dtk(double res) {
  const std::string path = data_file("3dtk_dat/3dtk_3scans.graph");
  if (path.empty()) return nullptr;
  auto out = std::make_unique<ShardedScans>();
  out->scans = std::make_unique<ScanSet>(load_scan_graph(path));
  const auto cfg = test_config(res, false);
  MapEngine engine(cfg.engine);
  std::vector<ShotScan> shots(out->scans->scans.size());
  out->whole = engine.make_tree();
  for (size_t k = 0; k < shots.size(); ++k) {
    const octomap::Pointcloud pts = world_points(out->scans->scans[k]);
    std::vector<octomap::point3d> points(pts.begin(), pts.end());
    engine.shoot(sensor_origin(out->scans->scans[k]), points, cfg.engine.max_range, shots[k]);
    ShotScan copy = shots[k];
    engine.apply(copy, *out->whole);
  }
  const double inf = std::numeric_limits<double>::infinity();
  const double lo[3] = {-inf, -inf, -inf}, hi[3] = {inf, inf, inf}, cut_max[3] = {inf, 0.0, inf},
               cut_min[3] = {-inf, 0.0, -inf};
  out->sharded.resize(2);
  out->sharded[0].what = "3 hashed shards, regions at depth 12";
  for (uint32_t i = 0; i < 3; ++i) {
    protocol::ShardSet s;
    s.index = i, s.count = 3, s.rule = protocol::ShardRule::kHash, s.region_depth = 12;
    out->sharded[0].sets.push_back(s);
  }
  out->sharded[1].what = "2 box shards cut at y = 0";
  for (uint32_t i = 0; i < 2; ++i) {
    protocol::ShardSet s;
    s.index = i, s.count = 2, s.rule = protocol::ShardRule::kBoxes, s.region_depth = 11;
    s.boxes = {protocol::region_box_of(lo, cut_max, res, 11), protocol::region_box_of(cut_min, hi, res, 11)};
    out->sharded[1].sets.push_back(s);
  }
  for (ShardMaps& m : out->sharded)
    for (const protocol::ShardSet& s : m.sets) {
      m.trees.push_back(engine.make_tree());
      for (const ShotScan& shot : shots) {
        ShotScan mine = shot;
        daemon::ShardFilter(s).keep_owned(mine);
        engine.apply(mine, *m.trees.back());
      }
    }
  return out;
}

}  // namespace ort::test
