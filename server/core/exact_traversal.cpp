#include "core/exact_traversal.h"

#include <algorithm>
#include <cmath>

namespace ort {
namespace {
constexpr int kTreeMaxVal = 32768;

int key_of(double c, double res) { return int(std::floor(c / res)) + kTreeMaxVal; }
}  // namespace

bool segment_touches_voxel(const double a[3], const double b[3], const int k[3], double res) {
  double t0 = 0.0, t1 = 1.0;
  for (int i = 0; i < 3; ++i) {
    const double lo = double(k[i] - kTreeMaxVal) * res;
    const double hi = double(k[i] - kTreeMaxVal + 1) * res;
    const double d = b[i] - a[i];
    if (d == 0.0) {
      if (a[i] < lo || a[i] > hi) return false;
      continue;
    }
    double ta = (lo - a[i]) / d;
    double tb = (hi - a[i]) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

void exact_ray_keys(const octomap::point3d& origin, const octomap::point3d& end, double resolution,
                    std::vector<octomap::OcTreeKey>& out) {
  const double a[3] = {origin.x(), origin.y(), origin.z()};
  const double b[3] = {end.x(), end.y(), end.z()};
  // Candidate enumeration, independent of any DDA: sweep x, then y, then z. On each axis
  // take the keys the segment spans within the parameter interval of the outer slabs,
  // widened by one voxel on each side (and each slab by one voxel of margin) so that
  // rounding never hides a voxel; the exact predicate then decides.
  int k[3];
  auto sweep = [&](auto&& self, int axis, double t0, double t1) -> void {
    const double d = b[axis] - a[axis];
    const double c0 = a[axis] + t0 * d, c1 = a[axis] + t1 * d;
    const int klo = std::max(0, std::min(key_of(c0, resolution), key_of(c1, resolution)) - 1);
    const int khi = std::min(2 * kTreeMaxVal - 1, std::max(key_of(c0, resolution), key_of(c1, resolution)) + 1);
    for (k[axis] = klo; k[axis] <= khi; ++k[axis]) {
      double s0 = t0, s1 = t1;
      if (d != 0.0) {
        const double lo = double(k[axis] - 1 - kTreeMaxVal) * resolution;
        const double hi = double(k[axis] + 2 - kTreeMaxVal) * resolution;
        double ta = (lo - a[axis]) / d, tb = (hi - a[axis]) / d;
        if (ta > tb) std::swap(ta, tb);
        s0 = std::max(s0, ta);
        s1 = std::min(s1, tb);
        if (s0 > s1) continue;
      }
      if (axis == 2) {
        if (segment_touches_voxel(a, b, k, resolution)) {
          out.emplace_back(octomap::key_type(k[0]), octomap::key_type(k[1]), octomap::key_type(k[2]));
        }
      } else {
        self(self, axis + 1, s0, s1);
      }
    }
  };
  sweep(sweep, 0, 0.0, 1.0);
}

}  // namespace ort
