#include "real_scan_voxels.h"

#include <span>

#include "engine/map_engine.h"
#include "scene/scan_set.h"
#include "support/test_data.h"

namespace ort::test {

std::vector<VoxelList> shoot_real_scans(const std::string& graph, size_t max_scans) {
  const std::string path = data_file(graph);
  if (path.empty()) return {};
  const ScanSet set = load_scan_graph(path);
  EngineOptions opts;
  opts.resolution = 0.1;
  opts.backend.kind = BackendKind::kCpu;
  MapEngine engine(opts);
  std::vector<VoxelList> lists;
  for (size_t i = 0; i < set.scans.size() && i < max_scans; ++i) {
    const octomap::Pointcloud world = world_points(set.scans[i]);
    ShotScan shot;
    engine.shoot(sensor_origin(set.scans[i]), std::span<const octomap::point3d>(&world[0], world.size()),
                 opts.max_range, shot);
    lists.push_back(std::move(shot.voxels));
  }
  return lists;
}

}  // namespace ort::test
