#include "real_scan_voxels.h"

#include <span>

#include "engine/map_engine.h"
#include "scene/scan_set.h"
#include "support/test_data.h"

namespace ort::test {

std::vector<VoxelList> shoot_real_scans(const std::string& graph, size_t max_scans, const ScanSplit& split) {
  const std::string path = data_file(graph);
  if (path.empty()) return {};
  const ScanSet set = load_scan_graph(path);
  EngineOptions opts;
  opts.resolution = 0.1;
  opts.backend.kind = BackendKind::kCpu;
  MapEngine engine(opts);
  std::vector<VoxelList> lists;
  for (size_t i = 0; i < set.scans.size() && i < max_scans; ++i) {
    const octomap::Pointcloud cloud = world_points(set.scans[i]);
    const octomap::point3d origin = sensor_origin(set.scans[i]);
    std::vector<octomap::point3d> world(cloud.begin(), cloud.end());
    std::vector<std::vector<octomap::point3d>> sets;
    if (split)
      sets = split(world, origin);
    else
      sets.push_back(std::move(world));
    for (const std::vector<octomap::point3d>& points : sets) {
      ShotScan shot;
      engine.shoot(origin, std::span<const octomap::point3d>(points.data(), points.size()), opts.max_range, shot);
      lists.push_back(std::move(shot.voxels));
    }
  }
  return lists;
}

}  // namespace ort::test
