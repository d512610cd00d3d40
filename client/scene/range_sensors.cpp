#include "scene/range_sensors.h"

#include <cmath>

namespace ort::scene {
namespace {

uint64_t splitmix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// Standard normal sample for (seed, index): Box-Muller on two hashed uniforms. Counter based,
// so the result does not depend on the order or the thread in which beams are cast.
double gaussian(uint64_t seed, uint64_t index) {
  const uint64_t a = splitmix64(seed ^ splitmix64(index * 2 + 1));
  const uint64_t b = splitmix64(a ^ 0x5851f42d4c957f2dull);
  const double u1 = (double((a >> 11) + 1)) * (1.0 / 9007199254740993.0);  // (0, 1]
  const double u2 = double(b >> 11) * (1.0 / 9007199254740992.0);          // [0, 1)
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

// Casts one sensor-frame unit direction and appends the noisy return, if any.
void cast_beam(const Scene& scene, const SensorPose& pose, const Vec3& dir_sensor, double min_range, double max_range,
               double sigma, uint64_t seed, uint64_t index, std::vector<Vec3>& out) {
  const Vec3 d = sensor_to_map(pose, dir_sensor);
  const double t = cast_ray(scene, pose.position, d, max_range);
  if (!(t >= min_range && t <= max_range)) return;
  const double r = t + sigma * gaussian(seed, index);
  if (r <= 0.0) return;
  out.push_back(dir_sensor * r);
}

}  // namespace

Vec3 sensor_to_map(const SensorPose& pose, const Vec3& v) {
  const double cp = std::cos(pose.pitch), sp = std::sin(pose.pitch);
  const double cy = std::cos(pose.yaw), sy = std::sin(pose.yaw);
  const double x1 = cp * v.x + sp * v.z, z1 = -sp * v.x + cp * v.z;  // pitch about y
  return {cy * x1 - sy * v.y, sy * x1 + cy * v.y, z1};               // yaw about z
}

void simulate_lidar(const Scene& scene, const SensorPose& pose, const LidarModel& m, uint64_t seed,
                    std::vector<Vec3>& out) {
  const double deg = M_PI / 180.0;
  for (int b = 0; b < m.beams; ++b) {
    const double elev = (m.beams == 1 ? 0.5 * (m.elev_min_deg + m.elev_max_deg)
                                      : m.elev_min_deg + (m.elev_max_deg - m.elev_min_deg) * b / (m.beams - 1)) *
                        deg;
    const double ce = std::cos(elev), se = std::sin(elev);
    for (int c = 0; c < m.columns; ++c) {
      const double az = 2.0 * M_PI * (c + 0.5) / m.columns;
      const Vec3 dir{ce * std::cos(az), ce * std::sin(az), se};
      cast_beam(scene, pose, dir, m.min_range, m.max_range, m.noise_sigma, seed, uint64_t(b) * m.columns + c, out);
    }
  }
}

void simulate_rgbd(const Scene& scene, const SensorPose& pose, const RgbdModel& m, uint64_t seed,
                   std::vector<Vec3>& out) {
  const double deg = M_PI / 180.0;
  // Pinhole camera: pixel (u, v) looks along (1, -(u - cx) / f, -(v - cy) / f), x forward.
  const double fx = 0.5 * m.width / std::tan(0.5 * m.hfov_deg * deg);
  const double fy = 0.5 * m.height / std::tan(0.5 * m.vfov_deg * deg);
  const double cx = 0.5 * m.width, cy = 0.5 * m.height;
  for (int v = 0; v < m.height; ++v) {
    for (int u = 0; u < m.width; ++u) {
      const uint64_t pixel = uint64_t(v) * m.width + u;
      if (m.dropout > 0 && double(splitmix64(seed ^ ~pixel) >> 11) * (1.0 / 9007199254740992.0) < m.dropout) continue;
      const Vec3 ray{1.0, -(u + 0.5 - cx) / fx, -(v + 0.5 - cy) / fy};
      const double len = std::sqrt(ray.x * ray.x + ray.y * ray.y + ray.z * ray.z);
      const Vec3 dir = ray * (1.0 / len);
      // Depth cameras cut by depth (z along the optical axis), not by range along the ray.
      const double t = cast_ray(scene, pose.position, sensor_to_map(pose, dir), m.max_range * len);
      const double depth = t / len;
      if (!(depth >= m.min_range && depth <= m.max_range)) continue;
      const double sigma = m.noise_base + m.noise_quad * (depth - 0.4) * (depth - 0.4);
      const double noisy = depth + sigma * gaussian(seed, pixel);
      if (noisy <= 0.0) continue;
      out.push_back(ray * noisy);
    }
  }
}

}  // namespace ort::scene
