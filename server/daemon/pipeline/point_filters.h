// The point filters octomap_server users know (its pointcloud_min/max_x/y/z pass-through, a
// sensor min range) applied to one scan's points before preparation, so that a filtered
// point gives neither a free ray nor an occupied end, as in octomap_server where PCL's
// PassThrough removes it from the cloud first. Plain CPU code; docs/PROTOCOL.md, "Point
// filters", has the table side by side with octomap_server's parameter names.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <octomap/octomap_types.h>

namespace ort::daemon {

// An axis-aligned pass-through box: PCL PassThrough's rule per axis, min <= v <= max (both
// limits kept). Infinite limits (the defaults) pass every finite value.
struct PassThroughBox {
  double min[3] = {-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                   -std::numeric_limits<double>::infinity()};
  double max[3] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::infinity()};
  bool limits_anything() const;
  bool passes(const octomap::point3d& p) const {
    for (int i = 0; i < 3; ++i)
      if (!(double(p(i)) >= min[i] && double(p(i)) <= max[i])) return false;
    return true;
  }
};

struct PointFilters {
  PassThroughBox map_frame;     // octomap_server's pointcloud_min/max_x/y/z (its cloud in the map frame)
  PassThroughBox sensor_frame;  // the same rule on the points as the sensor sent them (e.g. the robot's own body)
  double min_range = 0;         // points nearer the sensor than this [m] are dropped (no ray at all)
  bool active() const { return map_frame.limits_anything() || sensor_frame.limits_anything() || min_range > 0; }
};

// What the filters removed, by rule (a point is counted once, under the first rule it fails
// in this order: sensor frame, map frame, min range).
struct FilterCounts {
  uint64_t outside_sensor_box = 0, outside_map_box = 0, below_min_range = 0;
};

// Appends to `kept` the map-frame points world[i] that pass every filter; sensor[i] is the
// same point in the sensor frame (only read when the sensor box limits anything; it may then
// not be empty). The distance for the min range is OctoMap's (float, (p - origin).norm()).
// Non-finite points are kept: preparation counts them as non-finite (a no-return is not a
// filtered point).
void filter_points(const PointFilters& f, const octomap::point3d& origin, std::span<const octomap::point3d> world,
                   std::span<const octomap::point3d> sensor, std::vector<octomap::point3d>& kept, FilterCounts& counts);

// "" when the filters are usable; else why not (NaN limit, min above max, negative min range).
std::string check_point_filters(const PointFilters& f);

}  // namespace ort::daemon
