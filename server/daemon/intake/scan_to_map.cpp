#include "daemon/intake/scan_to_map.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/map_frame.h"

namespace ort::daemon {

octomap::pose6d scan_pose(const octomap_rt::scan_t& m) {
  const octomath::Vector3 t(static_cast<float>(m.sensor_position[0]), static_cast<float>(m.sensor_position[1]),
                            static_cast<float>(m.sensor_position[2]));
  const octomath::Quaternion q(static_cast<float>(m.sensor_orientation[0]), static_cast<float>(m.sensor_orientation[1]),
                               static_cast<float>(m.sensor_orientation[2]),
                               static_cast<float>(m.sensor_orientation[3]));
  return octomap::pose6d(t, q);
}

MapFrameScan to_map_frame(const octomap_rt::scan_t& m) {
  PosedMessageScan s = to_posed_scan(m);
  if (s.in_sensor_frame) transform_to_map_frame(s.points, s.pose);
  return {s.origin, std::move(s.points)};
}

PosedMessageScan to_posed_scan(const octomap_rt::scan_t& m) {
  PosedMessageScan s;
  s.pose = scan_pose(m);
  s.origin = s.pose.trans();
  s.in_sensor_frame = m.points_frame == octomap_rt::scan_t::POINTS_IN_SENSOR_FRAME;
  s.points.reserve(m.xyz.size() / 3);
  for (size_t i = 0; i + 2 < m.xyz.size(); i += 3) s.points.push_back(m.xyz[i], m.xyz[i + 1], m.xyz[i + 2]);
  return s;
}

RayLengths ray_lengths(const octomap_rt::scan_t& m, double max_range, double resolution) {
  const bool sensor_frame = m.points_frame == octomap_rt::scan_t::POINTS_IN_SENSOR_FRAME;
  // A rotation keeps lengths: in the sensor frame a ray is as long as its point's vector.
  const double ox = sensor_frame ? 0.0 : m.sensor_position[0], oy = sensor_frame ? 0.0 : m.sensor_position[1],
               oz = sensor_frame ? 0.0 : m.sensor_position[2];
  // Farther than twice the key range's side from an origin inside it, an uncut ray's end is
  // outside the key range: it gives no ray (skipped and counted as such), so it costs nothing.
  const double beyond_key_range = 2.0 * 65536.0 * resolution;
  RayLengths r;
  for (size_t i = 0; i + 2 < m.xyz.size(); i += 3) {
    const double dx = m.xyz[i] - ox, dy = m.xyz[i + 1] - oy, dz = m.xyz[i + 2] - oz;
    double len = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (!std::isfinite(len)) continue;
    if (max_range >= 0 && len > max_range) {
      len = max_range;  // cut there, as OctoMap cuts it (also when its end is outside the key range)
    } else if (len > beyond_key_range) {
      continue;
    }
    r.total_voxels += len / resolution;
    r.rays++;
  }
  return r;
}

double effective_max_range(float scan_max_range, double server_max_range) {
  if (scan_max_range > 0)
    return server_max_range > 0 ? std::min<double>(scan_max_range, server_max_range) : scan_max_range;
  return server_max_range;
}

}  // namespace ort::daemon
