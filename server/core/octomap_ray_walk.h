// OctoMap 1.9.7's ray walk (OcTreeBaseImpl::computeRayKeys, an Amanatides & Woo DDA) as an
// inline template that hands each free key to a callback instead of filling a KeyRay.
//
// The arithmetic is OctoMap's, operation for operation (float direction and length, double
// tMax/tDelta, the same comparison order), so the keys are identical to computeRayKeys'.
// That is what lets the native CPU back end and the GPU shaders be tested against OctoMap.
#pragma once

#include <cmath>
#include <limits>

#include <octomap/OcTreeKey.h>
#include <octomap/octomap_types.h>

namespace ort {

// The DDA's start, as computeRayKeys sets it up: the step sign of each axis, the ray
// parameter of the first voxel border along each axis (t_max), the parameter between borders
// (t_delta), and the segment's float length (the walk stops past it).
struct OctomapRayStart {
  int step[3];
  double t_max[3];
  double t_delta[3];
  float length;
};

inline OctomapRayStart octomap_ray_start(const octomap::point3d& origin, const octomap::point3d& end,
                                         const octomap::OcTreeKey& key_origin, double resolution) {
  constexpr int kTreeMaxVal = 32768;
  OctomapRayStart r;
  octomap::point3d direction = end - origin;
  r.length = (float)direction.norm();
  direction /= r.length;
  for (unsigned i = 0; i < 3; ++i) {
    if (direction(i) > 0.0)
      r.step[i] = 1;
    else if (direction(i) < 0.0)
      r.step[i] = -1;
    else
      r.step[i] = 0;
    if (r.step[i] != 0) {
      double voxel_border = (double((int)key_origin[i] - kTreeMaxVal) + 0.5) * resolution;  // keyToCoord
      voxel_border += (float)(r.step[i] * resolution * 0.5);
      r.t_max[i] = (voxel_border - origin(i)) / direction(i);
      r.t_delta[i] = resolution / std::fabs(direction(i));
    } else {
      r.t_max[i] = std::numeric_limits<double>::max();
      r.t_delta[i] = std::numeric_limits<double>::max();
    }
  }
  return r;
}

// The DDA itself, over a "stepper" that owns the current voxel. It calls
//   s.start(sx, sy, sz)        once, with the step sign of each axis (-1, 0, 1);
//   s.step_x() / step_y() / step_z() after each step along that axis; false stops the walk
//                              (the cpu-grid stepper stops where the ray leaves its window);
//   s.at_end()                 true when the current voxel is the end key's (the walk stops);
//   s.visit()                  for every voxel after the origin's, up to, excluding, the end voxel.
// The origin voxel is the caller's (walk_octomap_ray visits it first). Keys must already be
// known to be inside the key range (as computeRayKeys checks); key_origin != key_end.
template <class Stepper>
inline void walk_octomap_ray_steps(const octomap::point3d& origin, const octomap::point3d& end,
                                   const octomap::OcTreeKey& key_origin, double resolution, Stepper& s) {
  const OctomapRayStart r = octomap_ray_start(origin, end, key_origin, resolution);
  const float length = r.length;
  s.start(r.step[0], r.step[1], r.step[2]);
  // The loop keeps its state in registers (OctoMap indexes arrays by the stepping axis, a
  // chain through memory on every step); the comparisons and operations are the same.
  double tx = r.t_max[0], ty = r.t_max[1], tz = r.t_max[2];
  const double dx = r.t_delta[0], dy = r.t_delta[1], dz = r.t_delta[2];
  while (true) {
    if (tx < ty) {
      if (tx < tz) {
        if (!s.step_x()) return;
        tx += dx;
      } else {
        if (!s.step_z()) return;
        tz += dz;
      }
    } else if (ty < tz) {
      if (!s.step_y()) return;
      ty += dy;
    } else {
      if (!s.step_z()) return;
      tz += dz;
    }
    if (s.at_end()) return;
    const double dist_from_origin = std::min(std::min(tx, ty), tz);
    if (dist_from_origin > length) return;
    s.visit();
  }
}

// Walks origin -> end. Keys must already be known to be inside the key range (as
// computeRayKeys checks). Calls free_voxel(key) for the origin voxel and every voxel up to,
// but excluding, the end voxel; nothing when both lie in the same voxel.
template <class FreeVoxel>
inline void walk_octomap_ray(const octomap::point3d& origin, const octomap::point3d& end,
                             const octomap::OcTreeKey& key_origin, const octomap::OcTreeKey& key_end, double resolution,
                             FreeVoxel&& free_voxel) {
  if (key_origin == key_end) return;
  free_voxel(key_origin);
  struct KeyStepper {
    octomap::OcTreeKey current, end;
    FreeVoxel& f;
    octomap::key_type sx = 0, sy = 0, sz = 0;
    void start(int x, int y, int z) { sx = octomap::key_type(x), sy = octomap::key_type(y), sz = octomap::key_type(z); }
    bool step_x() {
      current[0] = octomap::key_type(current[0] + sx);
      return true;
    }
    bool step_y() {
      current[1] = octomap::key_type(current[1] + sy);
      return true;
    }
    bool step_z() {
      current[2] = octomap::key_type(current[2] + sz);
      return true;
    }
    bool at_end() const { return current == end; }
    void visit() { f(current); }
  } s{key_origin, key_end, free_voxel};
  walk_octomap_ray_steps(origin, end, key_origin, resolution, s);
}

}  // namespace ort
