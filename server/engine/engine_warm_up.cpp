#include "engine/engine_warm_up.h"

#include <chrono>
#include <cmath>
#include <numbers>
#include <vector>

#include "core/clock.h"

namespace ort {
namespace {

// Points spread evenly over a sphere (a Fibonacci lattice), x y z floats.
std::vector<float> sphere_points(size_t n, double radius) {
  std::vector<float> xyz;
  xyz.reserve(3 * n);
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (size_t i = 0; i < n; ++i) {
    const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / static_cast<double>(n);
    const double r = std::sqrt(1.0 - z * z), phi = golden * static_cast<double>(i);
    xyz.push_back(static_cast<float>(radius * r * std::cos(phi)));
    xyz.push_back(static_cast<float>(radius * r * std::sin(phi)));
    xyz.push_back(static_cast<float>(radius * z));
  }
  return xyz;
}

}  // namespace

WarmUpReport warm_up(MapEngine& engine, size_t points) {
  WarmUpReport report;
  if (points == 0) return report;
  report.points = points;
  const std::vector<float> xyz = sphere_points(points, kWarmUpRadiusVoxels * engine.options().resolution);
  const octomap::pose6d identity;
  ShotScan shot;
  const auto t0 = SteadyClock::now();
  engine.shoot_posed_xyz(identity, identity.trans(), xyz, engine.options().max_range, shot);
  report.shoot_ms = ms_since(t0);
  report.voxels = shot.voxels.size();
  report.refused = !shot.prepare.origin_ok || shot.refusal != ShotRefusal::kNone;
  const auto scratch = engine.make_tree();
  const auto t1 = SteadyClock::now();
  engine.apply(shot, *scratch);
  report.apply_ms = ms_since(t1);
  return report;
}

}  // namespace ort
