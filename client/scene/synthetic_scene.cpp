#include "scene/synthetic_scene.h"

#include <cmath>
#include <limits>
#include <vector>

namespace ort {
namespace {

struct Box {
  float lo[3], hi[3];
};

// Slab test; returns the entry distance along a unit direction, or infinity.
float hit_box(const octomap::point3d& o, const octomap::point3d& d, const Box& b) {
  float t0 = 0.0f, t1 = std::numeric_limits<float>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (d(i) == 0.0f) {
      if (o(i) < b.lo[i] || o(i) > b.hi[i]) return std::numeric_limits<float>::infinity();
      continue;
    }
    float ta = (b.lo[i] - o(i)) / d(i), tb = (b.hi[i] - o(i)) / d(i);
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return std::numeric_limits<float>::infinity();
  }
  return t0;
}

// Three rooms off a corridor: 18 m x 10 m x 3 m, walls 0.2 m thick, doors 1 m wide.
std::vector<Box> rooms() {
  std::vector<Box> b;
  b.push_back({{-1, -1, -0.2f}, {19, 11, 0}});  // floor
  b.push_back({{-1, -1, 3}, {19, 11, 3.2f}});   // ceiling
  b.push_back({{-1, -1, 0}, {19, -0.8f, 3}});   // outer walls
  b.push_back({{-1, 10.8f, 0}, {19, 11, 3}});
  b.push_back({{-1, -1, 0}, {-0.8f, 11, 3}});
  b.push_back({{18.8f, -1, 0}, {19, 11, 3}});
  // corridor wall at y = 3 with three doors
  b.push_back({{-1, 3, 0}, {2, 3.2f, 3}});
  b.push_back({{3, 3, 0}, {8, 3.2f, 3}});
  b.push_back({{9, 3, 0}, {14, 3.2f, 3}});
  b.push_back({{15, 3, 0}, {19, 3.2f, 3}});
  b.push_back({{6, 3.2f, 0}, {6.2f, 11, 3}});  // walls between the rooms
  b.push_back({{12, 3.2f, 0}, {12.2f, 11, 3}});
  b.push_back({{1, 7, 0}, {3, 8, 0.8f}});  // furniture
  b.push_back({{8, 8, 0}, {9.5f, 10, 1.2f}});
  b.push_back({{14, 5, 0}, {15, 6, 2.0f}});
  b.push_back({{10, 0.5f, 0}, {10.6f, 1.1f, 1.0f}});
  return b;
}

}  // namespace

ScanSet make_synthetic_rooms() {
  const std::vector<Box> scene = rooms();
  ScanSet set;
  set.name = "synthetic rooms (built-in)";
  // A 32-beam spinning range sensor, 720 columns, 30 m range, along the corridor and
  // into each room.
  const float poses[][3] = {{1.0f, 1.5f, 1.2f}, {5.5f, 1.4f, 1.2f},  {2.5f, 6.0f, 1.3f},
                            {9.0f, 6.0f, 1.1f}, {12.5f, 1.6f, 1.2f}, {16.0f, 7.0f, 1.2f}};
  const int beams = 32, columns = 720;
  for (const auto& p : poses) {
    PosedScan s;
    const float yaw = 0.3f * p[0];  // a different heading each pose
    s.pose = octomap::pose6d(p[0], p[1], p[2], 0.0, 0.0, yaw);
    const octomap::point3d origin(p[0], p[1], p[2]);
    for (int b = 0; b < beams; ++b) {
      const float elev = (-30.0f + 60.0f * b / (beams - 1)) * float(M_PI) / 180.0f;
      for (int c = 0; c < columns; ++c) {
        const float az = 2.0f * float(M_PI) * c / columns;
        // direction in the sensor frame, rotated into the map frame by yaw
        const octomap::point3d ds(std::cos(elev) * std::cos(az), std::cos(elev) * std::sin(az), std::sin(elev));
        const octomap::point3d dm(std::cos(yaw) * ds.x() - std::sin(yaw) * ds.y(),
                                  std::sin(yaw) * ds.x() + std::cos(yaw) * ds.y(), ds.z());
        float t = std::numeric_limits<float>::infinity();
        for (const Box& box : scene) t = std::min(t, hit_box(origin, dm, box));
        if (!(t < 30.0f)) continue;  // no return
        s.points.push_back(ds * t);  // sensor frame
      }
    }
    set.scans.push_back(std::move(s));
  }
  return set;
}

}  // namespace ort
