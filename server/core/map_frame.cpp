#include "core/map_frame.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace ort {
namespace {

#if defined(__x86_64__)
// A quaternion per lane: eight points' rotations at once.
struct QuatLanes {
  __m256 u, x, y, z;
};

__attribute__((target("avx2"))) QuatLanes broadcast(const MapFrameTransform::Quat& q) {
  return {_mm256_set1_ps(q.u), _mm256_set1_ps(q.x), _mm256_set1_ps(q.y), _mm256_set1_ps(q.z)};
}

// MapFrameTransform::mul term for term, left to right (a.u * o.u - a.x * o.x - ... is
// ((a.u * o.u - a.x * o.x) - a.y * o.y) - a.z * o.z in C++), in float lanes. The target
// enables AVX2 only (not FMA), so nothing is contracted.
__attribute__((target("avx2"), always_inline)) inline __m256 m(__m256 p, __m256 q) { return _mm256_mul_ps(p, q); }

__attribute__((target("avx2"))) QuatLanes mul(const QuatLanes& a, const QuatLanes& o) {
  return {_mm256_sub_ps(_mm256_sub_ps(_mm256_sub_ps(m(a.u, o.u), m(a.x, o.x)), m(a.y, o.y)), m(a.z, o.z)),
          _mm256_add_ps(_mm256_add_ps(_mm256_sub_ps(m(a.y, o.z), m(o.y, a.z)), m(a.u, o.x)), m(o.u, a.x)),
          _mm256_add_ps(_mm256_add_ps(_mm256_sub_ps(m(a.z, o.x), m(o.z, a.x)), m(a.u, o.y)), m(o.u, a.y)),
          _mm256_add_ps(_mm256_add_ps(_mm256_sub_ps(m(a.x, o.y), m(o.x, a.y)), m(a.u, o.z)), m(o.u, a.z))};
}

// Four points (12 floats: x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3) into x, y, z lanes, and back.
__attribute__((target("avx2"))) void load4(const float* f, __m128& x, __m128& y, __m128& z) {
  const __m128 a = _mm_loadu_ps(f), b = _mm_loadu_ps(f + 4), c = _mm_loadu_ps(f + 8);
  x = _mm_shuffle_ps(_mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 3, 0, 0)), _mm_shuffle_ps(b, c, _MM_SHUFFLE(1, 1, 2, 2)),
                     _MM_SHUFFLE(2, 0, 2, 0));
  y = _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 0, 1, 1)), _mm_shuffle_ps(b, c, _MM_SHUFFLE(2, 2, 3, 3)),
                     _MM_SHUFFLE(2, 0, 2, 0));
  z = _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 1, 2, 2)), _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 0, 0)),
                     _MM_SHUFFLE(2, 0, 2, 0));
}
__attribute__((target("avx2"))) void store4(float* f, __m128 x, __m128 y, __m128 z) {
  const __m128 xy_lo = _mm_unpacklo_ps(x, y), xy_hi = _mm_unpackhi_ps(x, y);  // x0 y0 x1 y1, x2 y2 x3 y3
  const __m128 z0x1 = _mm_shuffle_ps(z, xy_lo, _MM_SHUFFLE(2, 2, 0, 0));      // z0 z0 x1 x1
  const __m128 y1z1 = _mm_shuffle_ps(xy_lo, z, _MM_SHUFFLE(1, 1, 3, 3));      // y1 y1 z1 z1
  const __m128 z2x3 = _mm_shuffle_ps(z, xy_hi, _MM_SHUFFLE(2, 2, 2, 2));      // z2 z2 x3 x3
  const __m128 y3z3 = _mm_shuffle_ps(xy_hi, z, _MM_SHUFFLE(3, 3, 3, 3));      // y3 y3 z3 z3
  _mm_storeu_ps(f, _mm_shuffle_ps(xy_lo, z0x1, _MM_SHUFFLE(2, 0, 1, 0)));
  _mm_storeu_ps(f + 4, _mm_shuffle_ps(y1z1, xy_hi, _MM_SHUFFLE(1, 0, 2, 0)));
  _mm_storeu_ps(f + 8, _mm_shuffle_ps(z2x3, y3z3, _MM_SHUFFLE(2, 0, 2, 0)));
}

// Points [0, 8 * groups) of xyz into dst: (q * (0, v)) * inv + t, eight points a group.
__attribute__((target("avx2"))) void apply_avx2(const float* xyz, float* dst, size_t groups,
                                                const MapFrameTransform::Quat& q, const MapFrameTransform::Quat& inv,
                                                const float* t) {
  const QuatLanes ql = broadcast(q), il = broadcast(inv);
  const __m256 zero = _mm256_setzero_ps(), tx = _mm256_set1_ps(t[0]), ty = _mm256_set1_ps(t[1]),
               tz = _mm256_set1_ps(t[2]);
  for (size_t g = 0; g < groups; ++g) {
    const float* f = xyz + 24 * g;
    float* out = dst + 24 * g;
    __m128 x[2], y[2], z[2];
    load4(f, x[0], y[0], z[0]);
    load4(f + 12, x[1], y[1], z[1]);
    const QuatLanes v{zero, _mm256_set_m128(x[1], x[0]), _mm256_set_m128(y[1], y[0]), _mm256_set_m128(z[1], z[0])};
    const QuatLanes r = mul(mul(ql, v), il);
    const __m256 rx = _mm256_add_ps(r.x, tx), ry = _mm256_add_ps(r.y, ty), rz = _mm256_add_ps(r.z, tz);
    store4(out, _mm256_castps256_ps128(rx), _mm256_castps256_ps128(ry), _mm256_castps256_ps128(rz));
    store4(out + 12, _mm256_extractf128_ps(rx, 1), _mm256_extractf128_ps(ry, 1), _mm256_extractf128_ps(rz, 1));
  }
}
#endif

}  // namespace

void MapFrameTransform::apply(const float* xyz, octomap::point3d* dst, size_t n, bool simd) const {
  static_assert(sizeof(octomap::point3d) == 3 * sizeof(float), "a point3d is its three floats");
  size_t done = 0;
#if defined(__x86_64__)
  if (simd && n >= 8 && __builtin_cpu_supports("avx2")) {
    apply_avx2(xyz, &dst[0](0), n / 8, q_, inv_, t_);
    done = n / 8 * 8;
  }
#endif
  for (size_t i = done; i < n; ++i) dst[i] = (*this)(octomap::point3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]));
}

}  // namespace ort
