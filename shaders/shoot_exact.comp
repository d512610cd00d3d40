// Ray shooting, `exact` traversal: one invocation per ray; every voxel whose closed box the
// closed segment touches is free, the measured end voxel occupied (occupied wins).
//
// Candidates: a DDA walk from the key of the origin to the key of the end, always stepping
// towards the end key, and the 3x3x3 neighbourhood of every voxel it visits (tested as the
// start's 27 voxels, then the 9 new ones each step brings). The walk may be off by rounding
// near ties; the neighbourhood covers that, and exact_slab.glsl decides each candidate.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "flush_denormals.glsl"

#include "ray_space.glsl"
#include "exact_slab.glsl"

layout(local_size_x = 64) in;

const uint kMaxWalkSteps = 3u * 65536u;

int exact_key(double c) { return int(floor(c / resolution)) + kTreeMaxVal; }  // as exact_traversal.cpp

void test_and_mark(dvec3 a, dvec3 b, ivec3 k) {
  if (segment_touches_voxel(a, b, k, resolution)) mark_voxel(k, kStateFree);
}

void main() {
  const uint i = ray_base + gl_GlobalInvocationID.x;
  if (i >= ray_count) return;
  const RayEnd r = rays[i];
  if ((r.flags & kRayEndDropped) != 0u) return;  // a point GPU preparation dropped
  const vec3 end = vec3(r.x, r.y, r.z);
  const dvec3 a = dvec3(double(origin_x), double(origin_y), double(origin_z));
  const dvec3 b = dvec3(double(r.x), double(r.y), double(r.z));
  const ivec3 ka = ivec3(exact_key(a.x), exact_key(a.y), exact_key(a.z));
  const ivec3 kb = ivec3(exact_key(b.x), exact_key(b.y), exact_key(b.z));
  if (!box_meets_window(min(ka, kb) - 2, max(ka, kb) + 2)) return;
  if ((r.flags & 1u) != 0u) mark_voxel(coord_to_key(end), kStateOccupied);

  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) test_and_mark(a, b, ka + ivec3(dx, dy, dz));

  precise dvec3 d = b - a;
  ivec3 step_dir;
  precise dvec3 t_max;
  precise dvec3 t_delta;
  for (int k = 0; k < 3; ++k) {
    step_dir[k] = kb[k] > ka[k] ? 1 : (kb[k] < ka[k] ? -1 : 0);
    if (step_dir[k] != 0) {
      const double border = double(ka[k] - kTreeMaxVal + (step_dir[k] > 0 ? 1 : 0)) * resolution;
      t_max[k] = (border - a[k]) / d[k];
      t_delta[k] = resolution / abs(d[k]);
    } else {
      t_max[k] = 1.0e300LF;
      t_delta[k] = 0.0LF;
    }
  }
  ivec3 current = ka;
  for (uint n = 0u; n < kMaxWalkSteps && current != kb; ++n) {
    // The smallest tMax among the axes that still have to move: every step goes towards
    // kb, so the walk ends there after |kb - ka|_1 steps whatever the rounding.
    int dim = -1;
    for (int k = 0; k < 3; ++k) {
      if (current[k] != kb[k] && (dim < 0 || t_max[k] < t_max[dim])) dim = k;
    }
    current[dim] += step_dir[dim];
    t_max[dim] = t_max[dim] + t_delta[dim];
    const int u = (dim + 1) % 3, v = (dim + 2) % 3;
    const int layer = current[dim] + step_dir[dim];
    // Pre-filter (speed only): the part of the segment inside the new layer's slab, widened
    // by `slack`, spans these u and v coordinates; a candidate whose box lies beyond them
    // cannot touch the segment. The slack (1e-6 voxel, plus 1e-12 of the coordinates'
    // magnitude) dwarfs the rounding of either computation, so the exact predicate below
    // still decides every voxel that could possibly touch.
    const double slack = 1.0e-6LF * resolution + 1.0e-12LF * (abs(a[dim]) + abs(b[dim]) + abs(a[u]) + abs(b[u]) +
                                                               abs(a[v]) + abs(b[v]));
    const double slab_lo = double(layer - kTreeMaxVal) * resolution - slack;
    const double slab_hi = double(layer - kTreeMaxVal + 1) * resolution + slack;
    double s0 = (slab_lo - a[dim]) / d[dim];
    double s1 = (slab_hi - a[dim]) / d[dim];
    if (s0 > s1) {
      const double s = s0;
      s0 = s1;
      s1 = s;
    }
    s0 = max(s0, 0.0LF);
    s1 = min(s1, 1.0LF);
    if (s0 > s1) continue;
    const double u0 = a[u] + s0 * d[u], u1 = a[u] + s1 * d[u];
    const double v0 = a[v] + s0 * d[v], v1 = a[v] + s1 * d[v];
    const double u_lo = min(u0, u1) - slack, u_hi = max(u0, u1) + slack;
    const double v_lo = min(v0, v1) - slack, v_hi = max(v0, v1) + slack;
    for (int du = -1; du <= 1; ++du) {
      const int ku = current[u] + du;
      if (double(ku - kTreeMaxVal + 1) * resolution < u_lo || double(ku - kTreeMaxVal) * resolution > u_hi) continue;
      for (int dv = -1; dv <= 1; ++dv) {
        const int kv = current[v] + dv;
        if (double(kv - kTreeMaxVal + 1) * resolution < v_lo || double(kv - kTreeMaxVal) * resolution > v_hi) continue;
        ivec3 k;
        k[dim] = layer;
        k[u] = ku;
        k[v] = kv;
        test_and_mark(a, b, k);
      }
    }
  }
}
