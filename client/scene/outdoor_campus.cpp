// The outdoor campus world: roads on a grid, buildings between them, trees and cars.
#include <algorithm>
#include <cmath>
#include <vector>

#include "scene/procedural_worlds.h"
#include "scene/world_parts.h"

namespace ort::scene {

using namespace world_parts;

// ---- outdoor campus ----------------------------------------------------------------------

World make_outdoor_campus(uint64_t seed, const CampusParams& p) {
  Rng rng{seed * 0x9e3779b97f4a7c15ull + 7};
  const double L = p.length, D = p.width, rw = p.road_width;
  std::vector<Box> boxes;
  boxes.push_back(box(-20, -20, -0.3, L + 20, D + 20, 0));  // ground
  std::vector<double> ry, rx;                               // road centre lines
  for (int k = 0; k < p.roads_x; ++k) ry.push_back(6 + (D - 12) * k / std::max(1, p.roads_x - 1));
  for (int j = 0; j < p.roads_y; ++j) rx.push_back(6 + (L - 12) * j / std::max(1, p.roads_y - 1));
  auto near_crossing = [&](double v, const std::vector<double>& crossing) {
    for (double c : crossing)
      if (std::abs(v - c) < rw / 2 + 3) return true;
    return false;
  };
  std::vector<Rect> taken;  // building footprints, for placing trees
  // Buildings: one to three per block, set back from the roads.
  for (size_t k = 0; k + 1 < ry.size(); ++k) {
    for (size_t j = 0; j + 1 < rx.size(); ++j) {
      const double x0 = rx[j] + rw / 2 + 5, x1 = rx[j + 1] - rw / 2 - 5;
      const double y0 = ry[k] + rw / 2 + 5, y1 = ry[k + 1] - rw / 2 - 5;
      if (x1 - x0 < 8 || y1 - y0 < 8) continue;
      const int n = rng.integer(1, 3);
      const bool along_x = (x1 - x0) >= (y1 - y0);
      const double span = along_x ? x1 - x0 : y1 - y0, gap = 8.0;
      const double part = (span - gap * (n - 1)) / n;
      for (int i = 0; i < n; ++i) {
        const double a0 = (along_x ? x0 : y0) + i * (part + gap);
        const double la = part * rng.uniform(0.6, 1.0), lb = (along_x ? y1 - y0 : x1 - x0) * rng.uniform(0.4, 0.9);
        const double oa = a0 + rng.uniform(0, part - la),
                     ob = (along_x ? y0 : x0) + rng.uniform(0, (along_x ? y1 - y0 : x1 - x0) - lb);
        Rect f = along_x ? Rect{oa, ob, oa + la, ob + lb} : Rect{ob, oa, ob + lb, oa + la};
        const double h = rng.uniform(p.min_building_height, p.max_building_height);
        boxes.push_back(box(f.x0, f.y0, 0, f.x1, f.y1, h));
        taken.push_back(f);
        if (rng.chance(0.4)) {  // a lower wing: L-shaped buildings
          const double wx = (f.x1 - f.x0) * 0.4, wy = (f.y1 - f.y0) * 0.4;
          const Rect wing{f.x0, f.y0, f.x0 + wx, f.y0 + wy};
          boxes.push_back(box(wing.x0 - 3, wing.y0 - 3, 0, wing.x1, wing.y1, h * 0.5));
          taken.push_back({wing.x0 - 3, wing.y0 - 3, wing.x1, wing.y1});
        }
      }
    }
  }
  auto tree = [&](double x, double y) {
    const double trunk = rng.uniform(2.0, 4.0);
    boxes.push_back(box(x - 0.2, y - 0.2, 0, x + 0.2, y + 0.2, trunk));
    const int n = rng.integer(8, 14);
    const double cz = trunk + rng.uniform(1.0, 2.5);
    for (int i = 0; i < n; ++i) {  // the crown: a loose cluster of cubes
      const double e = rng.uniform(0.6, 1.6);
      const double bx = x + rng.normal(1.0), by = y + rng.normal(1.0), bz = std::max(trunk, cz + rng.normal(0.9));
      boxes.push_back(box(bx - e / 2, by - e / 2, bz - e / 2, bx + e / 2, by + e / 2, bz + e / 2));
    }
  };
  // Along the roads: trees and lamp posts beside them, cars parked at their edges. The road
  // centre, where the robot drives, stays clear.
  auto furnish_road = [&](bool along_x, double c, double a0, double a1, const std::vector<double>& crossing) {
    auto at = [&](double a, double off) { return along_x ? std::pair{a, c + off} : std::pair{c + off, a}; };
    for (double a = a0 + rng.uniform(0, p.tree_spacing); a < a1; a += p.tree_spacing * rng.uniform(0.7, 1.3)) {
      if (near_crossing(a, crossing)) continue;
      for (double side : {-1.0, 1.0}) {
        if (!rng.chance(0.7)) continue;
        const auto [x, y] = at(a, side * (rw / 2 + 2.0));
        tree(x, y);
      }
    }
    for (double a = a0 + 10; a < a1; a += 30) {
      if (near_crossing(a, crossing)) continue;
      const auto [x, y] = at(a, rw / 2 + 0.6);
      boxes.push_back(box(x - 0.08, y - 0.08, 0, x + 0.08, y + 0.08, 6.0));
      boxes.push_back(box(x - 0.3, y - 0.3, 5.8, x + 0.3, y + 0.3, 6.0));
    }
    for (double a = a0 + 3; a < a1; a += 7.0) {
      if (near_crossing(a, crossing) || near_crossing(a + 4.5, crossing) || !rng.chance(0.3)) continue;
      const double side = rng.chance(0.5) ? -1.0 : 1.0;
      // Body on four wheels (free space under it), 4.5 m x 1.8 m, at the road edge.
      const double o0 = side * (rw / 2 - 2.1), o1 = side * (rw / 2 - 0.3);
      auto car_box = [&](double a_lo, double a_hi, double off_lo, double off_hi, double z0, double z1) {
        if (along_x)
          boxes.push_back(box(a_lo, c + off_lo, z0, a_hi, c + off_hi, z1));
        else
          boxes.push_back(box(c + off_lo, a_lo, z0, c + off_hi, a_hi, z1));
      };
      car_box(a, a + 4.5, o0, o1, 0.3, 1.5);
      for (double f : {0.5, 3.4})
        for (double s : {o0, o1 - side * 0.3}) car_box(a + f, a + f + 0.6, s, s + side * 0.3, 0.0, 0.3);
    }
  };
  for (double c : ry) furnish_road(true, c, 0, L, rx);
  for (double c : rx) furnish_road(false, c, 0, D, ry);
  // Park trees inside the blocks, away from buildings.
  for (int i = 0; i < int(L * D / 600); ++i) {
    const double x = rng.uniform(0, L), y = rng.uniform(0, D);
    if (near_crossing(x, rx) || near_crossing(y, ry)) continue;
    const Rect spot{x - 3, y - 3, x + 3, y + 3};
    bool ok = true;
    for (const Rect& f : taken) ok = ok && !spot.overlaps(f);
    if (ok) tree(x, y);
  }
  // Serpentine over the roads along x, joined at alternate ends.
  const double z = p.sensor_height;
  Path path;
  for (size_t k = 0; k < ry.size(); ++k) {
    const bool east = k % 2 == 0;
    const double xa = east ? rx.front() : rx.back(), xb = east ? rx.back() : rx.front();
    path.push_back({xa, ry[k], z});
    path.push_back({xb, ry[k], z});
  }
  return finish(std::move(boxes), std::move(path), 1.0);
}
}  // namespace ort::scene
