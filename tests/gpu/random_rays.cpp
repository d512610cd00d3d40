#include "gpu/random_rays.h"

#include <cmath>
#include <cstdlib>

namespace ort::test {
namespace {

using octomap::point3d;

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}
int uniform_int(std::mt19937_64& rng, int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }

point3d random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  for (;;) {
    const double x = n(rng), y = n(rng), z = n(rng);
    const double l = std::sqrt(x * x + y * y + z * z);
    if (l > 1e-6) return point3d(float(x / l), float(y / l), float(z / l));
  }
}

// A coordinate on a voxel boundary: an integer multiple of the resolution, rounded to float
// the way a sensor's float would be.
float on_grid(std::mt19937_64& rng, double res, int range) { return float(uniform_int(rng, -range, range) * res); }

const double kResolutions[] = {0.1, 0.05, 0.2, 0.25, 0.5, 1.0, 0.15};

}  // namespace

uint64_t test_seed() {
  if (const char* s = std::getenv("OCTOMAP_RT_TEST_SEED")) return std::strtoull(s, nullptr, 10);
  return 20261122;
}

RandomScan random_scan(std::mt19937_64& rng) {
  RandomScan s;
  s.resolution = kResolutions[uniform_int(rng, 0, std::size(kResolutions) - 1)];
  const double res = s.resolution;
  const int rays = uniform_int(rng, 1, 8);
  const int kind = uniform_int(rng, 0, 9);
  auto random_point = [&](double half) {
    return point3d(float(uniform(rng, -half, half)), float(uniform(rng, -half, half)),
                   float(uniform(rng, -half, half)));
  };
  switch (kind) {
    case 0:  // random rays around the map's centre, negative coordinates included
    case 1: {
      s.kind = "random";
      s.origin = random_point(20.0);
      for (int i = 0; i < rays; ++i)
        s.points.push_back(s.origin + random_direction(rng) * float(uniform(rng, 0.0, 60 * res)));
      break;
    }
    case 2: {  // axis-aligned, from anywhere or from a voxel boundary
      s.kind = "axis";
      s.origin = random_point(10.0);
      if (uniform_int(rng, 0, 1))
        s.origin = point3d(on_grid(rng, res, 50), on_grid(rng, res, 50), on_grid(rng, res, 50));
      for (int i = 0; i < rays; ++i) {
        point3d d(0, 0, 0);
        d(uniform_int(rng, 0, 2)) = float(uniform(rng, -40 * res, 40 * res));
        s.points.push_back(s.origin + d);
      }
      break;
    }
    case 3: {  // in voxel faces: one or two coordinates on a boundary, shared by origin and end
      s.kind = "face";
      s.origin = random_point(10.0);
      const int fixed_axes = uniform_int(rng, 1, 2);
      const int first = uniform_int(rng, 0, 2);
      for (int a = 0; a < fixed_axes; ++a) s.origin((first + a) % 3) = on_grid(rng, res, 50);
      for (int i = 0; i < rays; ++i) {
        point3d p = s.origin + random_direction(rng) * float(uniform(rng, 0.0, 30 * res));
        for (int a = 0; a < fixed_axes; ++a) p((first + a) % 3) = s.origin((first + a) % 3);
        s.points.push_back(p);
      }
      break;
    }
    case 4: {  // through edges and corners: grid points to grid points, diagonals
      s.kind = "corner";
      s.origin = point3d(on_grid(rng, res, 60), on_grid(rng, res, 60), on_grid(rng, res, 60));
      for (int i = 0; i < rays; ++i) {
        const int n = uniform_int(rng, -12, 12);
        int m[3] = {n, uniform_int(rng, 0, 1) ? n : -n, uniform_int(rng, 0, 2) == 0 ? 0 : n};
        if (uniform_int(rng, 0, 2) == 0) m[uniform_int(rng, 0, 2)] = uniform_int(rng, -12, 12);
        s.points.emplace_back(float(s.origin.x() + m[0] * res), float(s.origin.y() + m[1] * res),
                              float(s.origin.z() + m[2] * res));
      }
      break;
    }
    case 5: {  // zero-length and sub-voxel rays
      s.kind = "short";
      s.origin = random_point(5.0);
      if (uniform_int(rng, 0, 1))
        s.origin = point3d(on_grid(rng, res, 20), on_grid(rng, res, 20), on_grid(rng, res, 20));
      for (int i = 0; i < rays; ++i) {
        const int how = uniform_int(rng, 0, 2);
        if (how == 0)
          s.points.push_back(s.origin);
        else
          s.points.push_back(s.origin + random_direction(rng) * float(uniform(rng, 0.0, how == 1 ? 1e-4 : res)));
      }
      break;
    }
    case 6: {  // near the +-32768-key edge of the map (some ends fall outside and are dropped)
      s.kind = "key_edge";
      const double edge = 32768 * res;
      point3d o;
      for (int a = 0; a < 3; ++a) {
        const double side = uniform_int(rng, 0, 1) ? 1.0 : -1.0;
        o(a) = uniform_int(rng, 0, 2) ? float(side * (edge - uniform(rng, 0.0, 8 * res))) : float(uniform(rng, -5, 5));
      }
      s.origin = o;
      for (int i = 0; i < rays; ++i)
        s.points.push_back(s.origin + random_direction(rng) * float(uniform(rng, 0.0, 10 * res)));
      break;
    }
    case 7: {  // far from the centre, negative
      s.kind = "far";
      s.origin = point3d(float(-uniform(rng, 0.3, 0.9) * 32768 * res), float(uniform(rng, -0.9, 0.9) * 32768 * res),
                         float(-uniform(rng, 0.0, 0.9) * 32768 * res));
      for (int i = 0; i < rays; ++i)
        s.points.push_back(s.origin + random_direction(rng) * float(uniform(rng, 0.0, 40 * res)));
      break;
    }
    default: {  // cut at max range: free space only, the cut end voxel not updated
      s.kind = "max_range";
      s.origin = random_point(10.0);
      s.max_range = uniform(rng, 2 * res, 20 * res);
      for (int i = 0; i < rays; ++i)
        s.points.push_back(s.origin + random_direction(rng) * float(uniform(rng, 0.0, 40 * res)));
      break;
    }
  }
  return s;
}

}  // namespace ort::test
