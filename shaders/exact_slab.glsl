// The closed segment / closed voxel box test of `exact` traversal, the same double
// operations in the same order as ort::segment_touches_voxel (server/core/
// exact_traversal.cpp), so GPU and CPU decide ties (faces, edges, corners) identically.
#ifndef EXACT_SLAB_GLSL
#define EXACT_SLAB_GLSL

bool segment_touches_voxel(dvec3 a, dvec3 b, ivec3 k, double res) {
  precise double t0 = 0.0LF;
  precise double t1 = 1.0LF;
  for (int i = 0; i < 3; ++i) {
    precise double lo = double(k[i] - 32768) * res;
    precise double hi = double(k[i] - 32768 + 1) * res;
    precise double d = b[i] - a[i];
    if (d == 0.0LF) {
      if (a[i] < lo || a[i] > hi) return false;
      continue;
    }
    precise double ta = (lo - a[i]) / d;
    precise double tb = (hi - a[i]) / d;
    if (ta > tb) {
      const double s = ta;
      ta = tb;
      tb = s;
    }
    t0 = t0 < ta ? ta : t0;  // std::max(t0, ta)
    t1 = tb < t1 ? tb : t1;  // std::min(t1, tb)
    if (t0 > t1) return false;
  }
  return true;
}

#endif
