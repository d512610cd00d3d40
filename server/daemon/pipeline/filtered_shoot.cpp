#include "daemon/pipeline/filtered_shoot.h"

#include <span>

#include "core/map_frame.h"
#include "daemon/intake/scan_to_map.h"

namespace ort::daemon {

FilterCounts shoot_filtered(MapEngine& engine, const octomap_rt::scan_t& msg, const PointFilters& filters,
                            double max_range, FilterScratch& scratch, ShotScan& out) {
  const octomap::pose6d pose = scan_pose(msg);
  const size_t n = msg.xyz.size() / 3;
  const std::span<const float> xyz(msg.xyz.data(), 3 * n);
  auto as_points = [&](std::vector<octomap::point3d>& v) {
    v.resize(n);
    for (size_t i = 0; i < n; ++i) v[i] = octomap::point3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  };
  const bool in_sensor_frame = msg.points_frame == octomap_rt::scan_t::POINTS_IN_SENSOR_FRAME;
  scratch.world.resize(n);
  if (in_sensor_frame) {
    // OctoMap's Pointcloud::transform, as the unfiltered path does (core/map_frame.h).
    transform_to_map_frame(xyz, scratch.world, pose, engine.options().octree.threads);
  } else {
    as_points(scratch.world);
  }
  scratch.sensor.clear();
  if (filters.sensor_frame.limits_anything()) {
    if (in_sensor_frame) {
      as_points(scratch.sensor);
    } else {  // points sent in the map frame: back into the sensor frame by the inverse pose
      const octomap::pose6d inverse = pose.inv();
      scratch.sensor.resize(n);
      for (size_t i = 0; i < n; ++i) scratch.sensor[i] = inverse.transform(scratch.world[i]);
    }
  }
  scratch.kept.clear();
  FilterCounts counts;
  filter_points(filters, pose.trans(), scratch.world, scratch.sensor, scratch.kept, counts);
  engine.shoot(pose.trans(), scratch.kept, max_range, out);
  return counts;
}

}  // namespace ort::daemon
