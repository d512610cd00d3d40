// Simulated range sensors: a spinning LiDAR and an RGB-D camera, ray cast against a Scene.
//
// Frames: the sensor frame has x forward, y left, z up (the robot convention OctoMap's data
// sets use). Points are returned in the sensor frame, as a ScanGraph stores them; the pose
// (position, yaw, pitch) places the sensor in the map. Noise is Gaussian along the beam and
// comes from a counter-based generator, so a scan depends only on its seed, never on the
// thread that made it.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene_geometry.h"

namespace ort::scene {

struct SensorPose {
  Vec3 position;
  double yaw = 0.0, pitch = 0.0;  // radians; roll is always 0 (a level robot)
};

// Spinning multi-beam LiDAR (or a tilting 2D scanner seen as one sweep).
struct LidarModel {
  int beams = 32;      // rows, spread evenly over [elev_min, elev_max]
  int columns = 1024;  // azimuth steps over 360 degrees
  double elev_min_deg = -30.0, elev_max_deg = 30.0;
  double min_range = 0.3, max_range = 30.0;
  double noise_sigma = 0.01;  // [m]
};

// Structured-light / time-of-flight RGB-D camera (PrimeSense-like by default).
struct RgbdModel {
  int width = 640, height = 480;
  double hfov_deg = 58.0, vfov_deg = 45.0;
  double min_range = 0.3, max_range = 8.0;
  // Depth noise sigma(z) = base + quad * (z - 0.4)^2 (a Kinect-style model).
  double noise_base = 0.0012, noise_quad = 0.0019;
  // Share of pixels with no depth at all (dark, shiny or grazing surfaces, speckle holes).
  double dropout = 0.1;
};

// Appends the scan's returns (sensor frame) to `out`. Beams with no surface between min and
// max range give no point, as real sensors report nothing there.
void simulate_lidar(const Scene& scene, const SensorPose& pose, const LidarModel& m, uint64_t seed,
                    std::vector<Vec3>& out);
void simulate_rgbd(const Scene& scene, const SensorPose& pose, const RgbdModel& m, uint64_t seed,
                   std::vector<Vec3>& out);

// Rotates a sensor-frame vector into the map frame (yaw about z after pitch about y), the
// rotation of octomap::pose6d(x, y, z, 0, pitch, yaw).
Vec3 sensor_to_map(const SensorPose& pose, const Vec3& v);

}  // namespace ort::scene
