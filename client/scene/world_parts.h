// The pieces both procedural worlds (indoor building, outdoor campus) are made of: a
// deterministic random generator, boxes, 2D footprints, and the world's final assembly.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "scene/procedural_worlds.h"

namespace ort::scene::world_parts {

// Small deterministic generator (splitmix64): the same seed gives the same world on every
// machine and standard library, unlike std::uniform_real_distribution.
struct Rng {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform(double a, double b) { return a + (b - a) * (double(next() >> 11) * (1.0 / 9007199254740992.0)); }
  int integer(int a, int b) { return a + int(next() % uint64_t(b - a + 1)); }  // inclusive
  bool chance(double p) { return uniform(0.0, 1.0) < p; }
  double normal(double sigma) {
    const double u1 = uniform(1e-12, 1.0), u2 = uniform(0.0, 1.0);
    return sigma * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
};

inline Box box(double x0, double y0, double z0, double x1, double y1, double z1) {
  return Box{{std::min(x0, x1), std::min(y0, y1), std::min(z0, z1)},
             {std::max(x0, x1), std::max(y0, y1), std::max(z0, z1)}};
}

// 2D rectangle, for keeping furniture, trees and cars off paths and out of each other.
struct Rect {
  double x0, y0, x1, y1;
  bool overlaps(const Rect& o, double margin = 0.0) const {
    return x0 < o.x1 + margin && o.x0 < x1 + margin && y0 < o.y1 + margin && o.y0 < y1 + margin;
  }
};

inline World finish(std::vector<Box> boxes, Path path, double cell) {
  World w;
  w.boxes = boxes.size();
  w.scene.boxes = build_box_grid(std::move(boxes), cell);
  w.lo = w.scene.boxes.lo;
  w.hi = w.scene.boxes.hi;
  w.path = std::move(path);
  return w;
}

}  // namespace ort::scene::world_parts
