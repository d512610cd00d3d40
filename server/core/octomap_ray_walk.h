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

// Walks origin -> end. Keys must already be known to be inside the key range (as
// computeRayKeys checks). Calls free_voxel(key) for the origin voxel and every voxel up to,
// but excluding, the end voxel; nothing when both lie in the same voxel.
template <class FreeVoxel>
inline void walk_octomap_ray(const octomap::point3d& origin, const octomap::point3d& end,
                             const octomap::OcTreeKey& key_origin, const octomap::OcTreeKey& key_end,
                             double resolution, FreeVoxel&& free_voxel) {
  constexpr int kTreeMaxVal = 32768;
  if (key_origin == key_end) return;
  free_voxel(key_origin);

  octomap::point3d direction = end - origin;
  const float length = (float)direction.norm();
  direction /= length;

  int step[3];
  double t_max[3];
  double t_delta[3];
  octomap::OcTreeKey current = key_origin;
  for (unsigned i = 0; i < 3; ++i) {
    if (direction(i) > 0.0) step[i] = 1;
    else if (direction(i) < 0.0) step[i] = -1;
    else step[i] = 0;
    if (step[i] != 0) {
      double voxel_border = (double((int)current[i] - kTreeMaxVal) + 0.5) * resolution;  // keyToCoord
      voxel_border += (float)(step[i] * resolution * 0.5);
      t_max[i] = (voxel_border - origin(i)) / direction(i);
      t_delta[i] = resolution / std::fabs(direction(i));
    } else {
      t_max[i] = std::numeric_limits<double>::max();
      t_delta[i] = std::numeric_limits<double>::max();
    }
  }
  // The loop keeps its state in registers (OctoMap indexes arrays by the stepping axis, a
  // chain through memory on every step); the comparisons and operations are the same.
  double tx = t_max[0], ty = t_max[1], tz = t_max[2];
  const double dx = t_delta[0], dy = t_delta[1], dz = t_delta[2];
  const auto sx = octomap::key_type(step[0]), sy = octomap::key_type(step[1]), sz = octomap::key_type(step[2]);
  while (true) {
    if (tx < ty) {
      if (tx < tz) {
        current[0] = octomap::key_type(current[0] + sx);
        tx += dx;
      } else {
        current[2] = octomap::key_type(current[2] + sz);
        tz += dz;
      }
    } else if (ty < tz) {
      current[1] = octomap::key_type(current[1] + sy);
      ty += dy;
    } else {
      current[2] = octomap::key_type(current[2] + sz);
      tz += dz;
    }
    if (current == key_end) return;
    const double dist_from_origin = std::min(std::min(tx, ty), tz);
    if (dist_from_origin > length) return;
    free_voxel(current);
  }
}

}  // namespace ort
