#include "scene/scene_presets.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>
#include <thread>

#include "scene/procedural_worlds.h"
#include "scene/range_sensors.h"
#include "scene/real_map_world.h"
#include "scene/trajectory.h"

namespace ort {
namespace {

using scene::LidarModel;
using scene::RgbdModel;
using scene::SensorPose;
using scene::World;

struct Sensor {
  bool rgbd = false;
  LidarModel lidar;
  RgbdModel camera;
};

struct Recipe {
  World world;
  Sensor sensor;
  int scans = 1;
  int robots = 1;
  scene::PathSampling sampling;
};

// FR-079: a SICK scanner on a pan-tilt unit gives ~89K points a sweep; 64 x 1400 beams over
// +-45 degrees, nearly all of which hit a wall, the floor or the ceiling.
LidarModel fr079_lidar() {
  LidarModel m;
  m.beams = 64;
  m.columns = 1400;
  m.elev_min_deg = -45;
  m.elev_max_deg = 45;
  m.max_range = 30;
  m.noise_sigma = 0.01;
  return m;
}

int scaled(int n, double s, int min) { return std::max(min, int(std::lround(n * s))); }

Recipe recipe(const std::string& name, const PresetOptions& o) {
  Recipe r;
  if (name == "fr079") {
    r.world = scene::make_indoor_building(o.seed, scene::IndoorParams{});
    r.sensor.lidar = fr079_lidar();
    r.scans = 66;
  } else if (name == "campus") {
    r.world = scene::make_outdoor_campus(o.seed, scene::CampusParams{});
    LidarModel& m = r.sensor.lidar;
    // Long range: most beams above the horizon hit a building or a tree crown far away, or
    // nothing (no point); ~247K returns a scan.
    m.beams = 128;
    m.columns = 3070;
    m.elev_min_deg = -30;
    m.elev_max_deg = 30;
    m.max_range = 60;
    m.noise_sigma = 0.03;
    r.scans = 81;
  } else if (name == "skt-corridor") {
    scene::IndoorParams p;
    p.length = 45.5;
    p.width = 33.3;
    p.height = 4.55;
    p.corridors_x = 2;
    p.corridors_y = 2;
    p.room_visits = 8;
    p.sensor_height = 1.1;
    r.world = scene::make_indoor_building(o.seed, p);
    r.sensor.rgbd = true;
    r.scans = 305;
    r.robots = 2;
    r.sampling.yaw_sweep_rad = 0.6;  // the camera looks around: walls, doors, down corridors
    r.sampling.sweep_period_m = 5.0;
    r.sampling.pitch_rad = 0.1;
  } else if (name == "fr079-real") {
    const std::string dir = o.data_dir.empty() ? std::string("../shared/data") : o.data_dir;
    r.world = scene::make_world_from_octomap(dir + "/octomap_share/geb079.bt", 1.0);
    r.sensor.lidar = fr079_lidar();
    r.scans = 66;
  } else {
    throw std::runtime_error("unknown preset '" + name + "'");
  }
  if (o.robots > 0) r.robots = o.robots;
  r.scans = scaled(r.scans, o.scan_scale, 1);
  r.robots = std::min(r.robots, r.scans);
  const double ps = std::sqrt(std::clamp(o.point_scale, 1e-6, 1.0));
  r.sensor.lidar.beams = scaled(r.sensor.lidar.beams, ps, 2);
  r.sensor.lidar.columns = scaled(r.sensor.lidar.columns, ps, 8);
  r.sensor.camera.width = scaled(r.sensor.camera.width, ps, 4);
  r.sensor.camera.height = scaled(r.sensor.camera.height, ps, 3);
  return r;
}

uint64_t scan_seed(uint64_t seed, size_t i) { return seed * 0x100000001b3ull ^ (uint64_t(i) * 0x9e3779b97f4a7c15ull); }

}  // namespace

const std::vector<PresetInfo>& preset_catalog() {
  static const std::vector<PresetInfo> catalog = {
      {"fr079", "indoor building, spinning LiDAR (FR-079 corridor-like)", 66, 89e3},
      {"campus", "outdoor campus, long-range LiDAR (Freiburg campus-like)", 81, 247e3},
      {"skt-corridor", "indoor corridors, RGB-D 640x480 0.3-8 m, two robots (Ewha-SKT corridor-like)", 305, 270e3},
      {"fr079-real", "OctoMap's real FR-079 map (geb079.bt) seen by a simulated LiDAR", 66, 89e3},
  };
  return catalog;
}

bool is_preset(const std::string& name) {
  for (const auto& p : preset_catalog())
    if (p.name == name) return true;
  return false;
}

double parse_scale(const std::string& s) {
  if (s == "tiny") return 0.02;
  if (s == "ci") return 0.05;
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(s, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != s.size() || !(v > 0.0 && v <= 1.0))
    throw std::invalid_argument("scale must be tiny, ci or a number in (0, 1], not '" + s + "'");
  return v;
}

ScanSet make_preset(const std::string& name, const PresetOptions& o) {
  const Recipe r = recipe(name, o);
  // Robots share the tour: robot k drives the k-th stretch of it, and their scans arrive
  // interleaved, as a mapping server receiving from a team would see them.
  const std::vector<SensorPose> along = scene::sample_path(
      r.world.path, {r.scans, r.sampling.yaw_sweep_rad, r.sampling.sweep_period_m, r.sampling.pitch_rad});
  std::vector<size_t> order;
  {
    std::vector<std::vector<size_t>> per_robot(r.robots);
    for (size_t i = 0; i < along.size(); ++i) per_robot[i * r.robots / along.size()].push_back(i);
    for (size_t k = 0; order.size() < along.size(); ++k)
      for (const auto& mine : per_robot)
        if (k < mine.size()) order.push_back(mine[k]);
  }
  ScanSet set;
  set.name = name;
  set.scans.resize(order.size());
  std::atomic<size_t> next{0};
  auto work = [&] {
    std::vector<scene::Vec3> pts;
    for (size_t i; (i = next++) < order.size();) {
      const SensorPose& pose = along[order[i]];
      pts.clear();
      if (r.sensor.rgbd)
        scene::simulate_rgbd(r.world.scene, pose, r.sensor.camera, scan_seed(o.seed, order[i]), pts);
      else
        scene::simulate_lidar(r.world.scene, pose, r.sensor.lidar, scan_seed(o.seed, order[i]), pts);
      PosedScan& s = set.scans[i];
      s.pose = octomap::pose6d(pose.position.x, pose.position.y, pose.position.z, 0.0, pose.pitch, pose.yaw);
      s.points.reserve(pts.size());
      for (const auto& p : pts) s.points.push_back(float(p.x), float(p.y), float(p.z));
    }
  };
  const unsigned n = o.threads ? o.threads : std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < n; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  return set;
}

}  // namespace ort
