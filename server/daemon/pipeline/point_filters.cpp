#include "daemon/pipeline/point_filters.h"

#include <cmath>
#include <string>

namespace ort::daemon {
namespace {
bool finite(const octomap::point3d& p) { return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()); }
}  // namespace

bool PassThroughBox::limits_anything() const {
  for (int i = 0; i < 3; ++i)
    if (std::isfinite(min[i]) || std::isfinite(max[i])) return true;
  return false;
}

void filter_points(const PointFilters& f, const octomap::point3d& origin, std::span<const octomap::point3d> world,
                   std::span<const octomap::point3d> sensor, std::vector<octomap::point3d>& kept,
                   FilterCounts& counts) {
  const bool sensor_box = f.sensor_frame.limits_anything(), map_box = f.map_frame.limits_anything();
  kept.reserve(kept.size() + world.size());
  for (size_t i = 0; i < world.size(); ++i) {
    const octomap::point3d& p = world[i];
    if (finite(p) && (!sensor_box || finite(sensor[i]))) {
      if (sensor_box && !f.sensor_frame.passes(sensor[i])) {
        ++counts.outside_sensor_box;
        continue;
      }
      if (map_box && !f.map_frame.passes(p)) {
        ++counts.outside_map_box;
        continue;
      }
      if (f.min_range > 0 && (p - origin).norm() < f.min_range) {
        ++counts.below_min_range;
        continue;
      }
    }
    kept.push_back(p);
  }
}

std::string check_point_filters(const PointFilters& f) {
  const char* axis = "xyz";
  for (const auto& [box, frame] : {std::pair{&f.map_frame, "map-frame"}, std::pair{&f.sensor_frame, "sensor-frame"}})
    for (int i = 0; i < 3; ++i) {
      if (std::isnan(box->min[i]) || std::isnan(box->max[i]))
        return std::string(frame) + " limit on " + axis[i] + " is NaN";
      if (box->min[i] > box->max[i])
        return std::string(frame) + " limits on " + axis[i] + ": min " + std::to_string(box->min[i]) + " above max " +
               std::to_string(box->max[i]);
    }
  if (!(f.min_range >= 0 && std::isfinite(f.min_range)))
    return "min range must be a finite number of metres >= 0, not " + std::to_string(f.min_range);
  return "";
}

}  // namespace ort::daemon
