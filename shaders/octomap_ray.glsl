// OctoMap 1.9.7's OcTreeBaseImpl::computeRayKeys (Amanatides & Woo), operation for
// operation: float direction and length, double tMax/tDelta, the same comparison order and
// the same stopping rules. `precise` forbids fused multiply-adds the CPU does not make;
// float divisions are done in double and rounded once to float, because NVIDIA's fp32
// division is not IEEE (../shared/notes/gpu-arithmetic-and-atomics.md) while the rounded
// double quotient is exactly the IEEE float quotient.
#ifndef OCTOMAP_RAY_GLSL
#define OCTOMAP_RAY_GLSL

#include "ray_space.glsl"

const double kDblMax = 1.7976931348623157e308LF;
const uint kMaxWalkSteps = 3u * 65536u;  // guard only; OctoMap's walk ends long before

// Marks every voxel computeRayKeys would return for origin -> end as free: the origin
// voxel first, then the walk up to but excluding the end voxel; nothing if both coincide.
void walk_octomap_ray(vec3 origin, ivec3 key_origin, vec3 end, ivec3 key_end) {
  if (key_origin == key_end) return;
  mark_voxel(key_origin, kStateFree);

  precise vec3 direction = end - origin;
  precise float norm_sq = direction.x * direction.x + direction.y * direction.y;
  norm_sq = norm_sq + direction.z * direction.z;  // Vector3::norm_sq: (x*x + y*y) + z*z in float
  const float len = float(sqrt(double(norm_sq)));  // (float) sqrt(double)
  precise vec3 dir;
  dir.x = float(double(direction.x) / double(len));
  dir.y = float(double(direction.y) / double(len));
  dir.z = float(double(direction.z) / double(len));

  ivec3 step_dir;
  precise dvec3 t_max;
  precise dvec3 t_delta;
  for (int i = 0; i < 3; ++i) {
    step_dir[i] = dir[i] > 0.0 ? 1 : (dir[i] < 0.0 ? -1 : 0);
    if (step_dir[i] != 0) {
      precise double border = (double(key_origin[i] - kTreeMaxVal) + 0.5LF) * resolution;  // keyToCoord
      border = border + double(float(double(step_dir[i]) * resolution * 0.5LF));
      t_max[i] = (border - double(origin[i])) / double(dir[i]);
      t_delta[i] = resolution / double(abs(dir[i]));
    } else {
      t_max[i] = kDblMax;
      t_delta[i] = kDblMax;
    }
  }

  // Keys are OctoMap's uint16 key_type: wrap as it does.
  ivec3 current = key_origin;
  for (uint n = 0u; n < kMaxWalkSteps; ++n) {
    int dim;
    if (t_max.x < t_max.y) dim = t_max.x < t_max.z ? 0 : 2;
    else dim = t_max.y < t_max.z ? 1 : 2;
    current[dim] = (current[dim] + step_dir[dim]) & 0xFFFF;
    t_max[dim] = t_max[dim] + t_delta[dim];
    if (current == key_end) return;
    const double dist_from_origin = min(min(t_max.x, t_max.y), t_max.z);
    if (dist_from_origin > double(len)) return;
    mark_voxel(current, kStateFree);
  }
  atomicAdd(walk_overruns, 1u);
}

#endif
