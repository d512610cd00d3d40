// rays_stay_inside (cpu/window_walk_avx2.h): whether a batch's walks can leave a window,
// decided in AVX2 lanes from the rays' end keys; walk_rays_avx2 drops its per-step exit test
// where they cannot.
#include "cpu/window_walk_avx2.h"

#include <algorithm>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace ort {

#if defined(__x86_64__)

__attribute__((target("avx2"))) bool rays_stay_inside(const RayBatch& b, size_t begin, size_t end,
                                                      const BrickLayout& layout, double res) {
  constexpr int kTreeMaxVal = 32768, kInsideBy = 2;
  const KeyBox& w = layout.window();
  __m256i lo[3], hi[3];
  for (int i = 0; i < 3; ++i) {
    if (b.origin_key[i] < w.lo[i] + kInsideBy || b.origin_key[i] > w.hi[i] - kInsideBy) return false;
    lo[i] = _mm256_set1_epi64x(int64_t(w.lo[i]) + kInsideBy - kTreeMaxVal);  // in floor(coord / res) units
    hi[i] = _mm256_set1_epi64x(int64_t(w.hi[i]) - kInsideBy - kTreeMaxVal);
  }
  if (b.keys_hold_ends) {  // the batch's box decides without a pass over the rays
    bool inside = true;
    for (int i = 0; i < 3; ++i)
      inside = inside && b.keys.lo[i] >= w.lo[i] + kInsideBy && b.keys.hi[i] <= w.hi[i] - kInsideBy;
    return inside;
  }
  __m256i outside = _mm256_setzero_si256();
  for (size_t r = begin; r < end; r += 4) {
    const size_t n = std::min<size_t>(4, end - r);
    __m128 e[4];
    for (size_t j = 0; j < 4; ++j) e[j] = _mm_loadu_ps(&b.ends[r + std::min(j, n - 1)].x);
    _MM_TRANSPOSE4_PS(e[0], e[1], e[2], e[3]);
    for (int i = 0; i < 3; ++i) {
      const __m256d scaled = _mm256_mul_pd(_mm256_set1_pd(1.0 / res), _mm256_cvtps_pd(e[i]));
      const __m256i key = _mm256_cvtepi32_epi64(
          _mm256_cvttpd_epi32(_mm256_round_pd(scaled, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)));
      outside =
          _mm256_or_si256(outside, _mm256_or_si256(_mm256_cmpgt_epi64(lo[i], key), _mm256_cmpgt_epi64(key, hi[i])));
    }
  }
  return _mm256_testz_si256(outside, outside);
}

#else

bool rays_stay_inside(const RayBatch&, size_t, size_t, const BrickLayout&, double) { return false; }

#endif

}  // namespace ort
