// Robot trajectories: sensor poses spaced evenly along a polyline path.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/range_sensors.h"

namespace ort::scene {

// A path in the map frame: waypoints at sensor height.
using Path = std::vector<Vec3>;

struct PathSampling {
  int count = 10;               // poses along the whole path
  double yaw_sweep_rad = 0.0;   // heading = path tangent + sweep * sin(phase): a camera looking around
  double sweep_period_m = 6.0;  // path length of one sweep period
  double pitch_rad = 0.0;       // constant sensor pitch (a camera tilted down)
};

// `count` poses at equal arc-length steps, first and last waypoints included.
std::vector<SensorPose> sample_path(const Path& path, const PathSampling& s);

double path_length(const Path& path);

}  // namespace ort::scene
