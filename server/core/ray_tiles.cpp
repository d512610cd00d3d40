#include "core/ray_tiles.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <unordered_map>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace ort {
namespace {

constexpr int kKeyMax = 65535;
constexpr double kTreeMaxVal = 32768.0;

// Continuous key coordinate of a map coordinate (floor gives OctoMap's key).
double key_coord(double v, double res) { return v / res + kTreeMaxVal; }

// clamp(floor(k), 0, kKeyMax) without std::floor (a libm call without SSE4.1; this runs for
// every ray of every scan): below 0 -> 0, from kKeyMax on -> kKeyMax, between them floor is
// the truncation of a non-negative value. NaN, which never reaches here (prepare_scan drops
// non-finite points), gives 0.
int clamp_key(double k) {
  if (!(k >= 0.0)) return 0;
  if (k >= double(kKeyMax)) return kKeyMax;
  return static_cast<int>(k);
}

using TileSet = std::array<uint32_t, 8>;

// Calls f(tile_id) once for every distinct tile the ray's pieces touch, in order along the
// ray (the tiles a straight segment touches are touched by consecutive pieces, so comparing
// with the previous piece's tiles removes every repeat).
template <class F>
void for_each_tile(const RayBatch& b, const RayEnd& e, int side, int margin, const KeyBox& clip, F&& f) {
  const double o[3] = {key_coord(b.origin.x(), b.resolution), key_coord(b.origin.y(), b.resolution),
                       key_coord(b.origin.z(), b.resolution)};
  const double d[3] = {key_coord(e.x, b.resolution) - o[0], key_coord(e.y, b.resolution) - o[1],
                       key_coord(e.z, b.resolution) - o[2]};
  const double extent = std::max({std::abs(d[0]), std::abs(d[1]), std::abs(d[2])});
  const int pieces = 1 + static_cast<int>(extent / (side / 2.0));
  const uint32_t per_axis = (kKeyMax + 1) / uint32_t(side) + 1;
  TileSet prev{}, cur{};
  size_t n_prev = 0;
  for (int p = 0; p < pieces; ++p) {
    int lo[3], hi[3];
    for (int i = 0; i < 3; ++i) {
      const double a = o[i] + d[i] * (double(p) / pieces), z = o[i] + d[i] * (double(p + 1) / pieces);
      lo[i] = std::max(clip.lo[i], clamp_key(std::min(a, z)) - margin) / side;
      hi[i] = std::min(clip.hi[i], clamp_key(std::max(a, z)) + margin) / side;
    }
    size_t n_cur = 0;
    for (int tz = lo[2]; tz <= hi[2]; ++tz)
      for (int ty = lo[1]; ty <= hi[1]; ++ty)
        for (int tx = lo[0]; tx <= hi[0]; ++tx) {
          const uint32_t id = uint32_t(tx) + per_axis * (uint32_t(ty) + per_axis * uint32_t(tz));
          if (n_cur < cur.size()) cur[n_cur++] = id;
          if (std::find(prev.begin(), prev.begin() + n_prev, id) == prev.begin() + n_prev) f(id);
        }
    prev = cur;
    n_prev = n_cur;
  }
}

KeyBox widened_keys(const RayBatch& b, int margin) {
  KeyBox w = b.keys;
  for (int i = 0; i < 3; ++i) {
    w.lo[i] = std::max(0, w.lo[i] - margin);
    w.hi[i] = std::min(kKeyMax, w.hi[i] + margin);
  }
  return w;
}

KeyBox tile_box(uint32_t id, int side, const KeyBox& clip) {
  const uint32_t per_axis = (kKeyMax + 1) / uint32_t(side) + 1;
  const uint32_t t[3] = {id % per_axis, id / per_axis % per_axis, id / per_axis / per_axis};
  KeyBox box;
  for (int i = 0; i < 3; ++i) {
    box.lo[i] = std::max(clip.lo[i], int(t[i]) * side);
    box.hi[i] = std::min(clip.hi[i], int(t[i]) * side + side - 1);
  }
  return box;
}

}  // namespace

uint64_t ray_walk_keys(const RayBatch& batch, const RayEnd& e) {
  const double c[3] = {e.x, e.y, e.z};
  uint64_t n = 1;
  for (int i = 0; i < 3; ++i) {
    const int key = clamp_key(key_coord(c[i], batch.resolution));
    n += uint64_t(std::abs(key - int(batch.origin_key[i])));
  }
  return n;
}

namespace {

#if defined(__x86_64__)
// ray_walk_keys of rays [0, 4 * groups) in AVX2 lanes: key_coord's v / res + 32768 in double,
// clamp_key as max(k, 0) (MAXPD returns its second operand, 0, for NaN and for -0.0) then
// min(k, 65535) and truncation, |key - origin key| summed over the axes.
__attribute__((target("avx2"))) WalkKeyTotals walk_keys_avx2(const RayBatch& b, size_t groups) {
  const __m256d res = _mm256_set1_pd(b.resolution), max_val = _mm256_set1_pd(kTreeMaxVal);
  const __m256d zero = _mm256_setzero_pd(), key_max = _mm256_set1_pd(double(kKeyMax));
  const __m128i origin[3] = {_mm_set1_epi32(b.origin_key[0]), _mm_set1_epi32(b.origin_key[1]),
                             _mm_set1_epi32(b.origin_key[2])};
  __m256i sum = _mm256_setzero_si256();
  __m128i longest = _mm_setzero_si128();
  for (size_t g = 0; g < groups; ++g) {
    __m128 c[4];  // x, y, z, flags of four rays
    for (int j = 0; j < 4; ++j) c[j] = _mm_loadu_ps(&b.ends[4 * g + j].x);
    _MM_TRANSPOSE4_PS(c[0], c[1], c[2], c[3]);
    __m128i n = _mm_set1_epi32(1);
    for (int i = 0; i < 3; ++i) {
      const __m256d k = _mm256_add_pd(_mm256_div_pd(_mm256_cvtps_pd(c[i]), res), max_val);
      const __m128i key = _mm256_cvttpd_epi32(_mm256_min_pd(_mm256_max_pd(k, zero), key_max));
      n = _mm_add_epi32(n, _mm_abs_epi32(_mm_sub_epi32(key, origin[i])));
    }
    sum = _mm256_add_epi64(sum, _mm256_cvtepu32_epi64(n));
    longest = _mm_max_epu32(longest, n);
  }
  alignas(32) uint64_t s[4];
  alignas(16) uint32_t l[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(s), sum);
  _mm_store_si128(reinterpret_cast<__m128i*>(l), longest);
  return {s[0] + s[1] + s[2] + s[3], std::max({l[0], l[1], l[2], l[3]})};
}
#endif

}  // namespace

WalkKeyTotals batch_walk_keys(const RayBatch& batch, bool simd) {
  WalkKeyTotals t;
  size_t done = 0;
#if defined(__x86_64__)
  if (simd && __builtin_cpu_supports("avx2")) {
    t = walk_keys_avx2(batch, batch.ends.size() / 4);
    done = batch.ends.size() / 4 * 4;
  }
#endif
  for (size_t i = done; i < batch.ends.size(); ++i) {
    const uint64_t k = ray_walk_keys(batch, batch.ends[i]);
    t.sum += k;
    t.longest = std::max(t.longest, k);
  }
  return t;
}

uint64_t tiled_walk_keys(const RayBatch& batch, int side, int margin) {
  const KeyBox clip = widened_keys(batch, margin);
  uint64_t total = 0;
  for (const RayEnd& e : batch.ends) {
    const uint64_t walk = ray_walk_keys(batch, e);
    for_each_tile(batch, e, side, margin, clip, [&](uint32_t) { total += walk; });
  }
  return total;
}

TilePlan plan_ray_tiles(const RayBatch& batch, int side, int margin) {
  TilePlan plan;
  const KeyBox clip = widened_keys(batch, margin);
  std::unordered_map<uint32_t, size_t> index;
  for (uint32_t r = 0; r < batch.ends.size(); ++r) {
    const uint64_t walk = ray_walk_keys(batch, batch.ends[r]);
    for_each_tile(batch, batch.ends[r], side, margin, clip, [&](uint32_t id) {
      auto [it, fresh] = index.try_emplace(id, plan.tiles.size());
      if (fresh) plan.tiles.push_back(RayTile{tile_box(id, side, clip), {}});
      std::vector<uint32_t>& rays = plan.tiles[it->second].rays;
      if (rays.empty() || rays.back() != r) {
        rays.push_back(r);
        plan.walk_keys += walk;
      }
    });
  }
  return plan;
}

}  // namespace ort
