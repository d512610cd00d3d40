#include "scene/trajectory.h"

#include <cmath>

namespace ort::scene {

double path_length(const Path& path) {
  double len = 0.0;
  for (size_t i = 1; i < path.size(); ++i) {
    const Vec3 d = path[i] - path[i - 1];
    len += std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  }
  return len;
}

std::vector<SensorPose> sample_path(const Path& path, const PathSampling& s) {
  std::vector<SensorPose> poses;
  if (path.empty() || s.count <= 0) return poses;
  const double total = path_length(path);
  size_t seg = 0;
  double seg_start = 0.0;  // arc length at path[seg]
  for (int k = 0; k < s.count; ++k) {
    const double at = s.count == 1 ? 0.0 : total * k / (s.count - 1);
    // advance to the segment holding arc length `at`
    while (seg + 1 < path.size()) {
      const Vec3 d = path[seg + 1] - path[seg];
      const double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
      if (at <= seg_start + len || seg + 2 == path.size()) break;
      seg_start += len;
      ++seg;
    }
    SensorPose p;
    if (path.size() == 1) {
      p.position = path[0];
    } else {
      const Vec3 d = path[seg + 1] - path[seg];
      const double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
      const double f = len > 0 ? std::min(1.0, std::max(0.0, (at - seg_start) / len)) : 0.0;
      p.position = path[seg] + d * f;
      p.yaw = std::atan2(d.y, d.x);
    }
    if (s.yaw_sweep_rad != 0.0) p.yaw += s.yaw_sweep_rad * std::sin(2.0 * M_PI * at / s.sweep_period_m);
    p.pitch = s.pitch_rad;
    poses.push_back(p);
  }
  return poses;
}

}  // namespace ort::scene
