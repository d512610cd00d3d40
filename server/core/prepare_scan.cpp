#include "core/prepare_scan.h"

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace ort {
namespace {
bool finite(const octomap::point3d& p) { return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()); }
}  // namespace

namespace {

// One contiguous share of a scan's points, prepared on its own thread.
struct PreparedChunk {
  std::vector<RayEnd> ends;
  KeyBox keys;
  PrepareReport report;
};

// OctoMap's rules for one point: false when it gives no ray (counted in `report`), else its
// ray end and end key.
bool prepare_point(const octomap::point3d& origin, const octomap::OcTreeKey& origin_key, const octomap::point3d& given,
                   double max_range, double resolution, PrepareReport& report, RayEnd& ray,
                   octomap::OcTreeKey& end_key) {
  if (!finite(given)) {
    ++report.nonfinite;
    return false;
  }
  const octomap::point3d p = read_tiny_as_zero(given);  // the scan contract (prepare_scan.h)
  if (has_tiny_coordinate(given)) ++report.read_as_zero;
  // OccupancyOcTreeBase::computeUpdate, no bounding box: a measurement within max range
  // frees its ray and occupies its end; a longer one is cut at max range, free only.
  octomap::point3d end = p;
  uint32_t flags = kRayEndOccupied;
  if (!(max_range < 0.0) && !((p - origin).norm() <= max_range)) {
    const octomap::point3d direction = (p - origin).normalized();
    end = origin + direction * (float)max_range;
    flags = 0;
    ++report.cut_at_max_range;
  }
  if (!coord_to_key_checked(end, resolution, end_key)) {
    ++report.out_of_range;
    return false;
  }
  if (degenerate_ray(origin, end, origin_key, end_key)) {
    ++report.degenerate;
    return false;
  }
  ray = RayEnd{end.x(), end.y(), end.z(), flags};
  return true;
}

void prepare_points(const octomap::point3d& origin, const octomap::OcTreeKey& origin_key,
                    std::span<const octomap::point3d> points, double max_range, double resolution, PreparedChunk& out) {
  RayEnd ray;
  octomap::OcTreeKey key;
  for (const octomap::point3d& p : points) {
    if (!prepare_point(origin, origin_key, p, max_range, resolution, out.report, ray, key)) continue;
    out.keys.include(key);
    out.ends.push_back(ray);
  }
}

#if defined(__x86_64__)
// The common case four points at a time (AVX2): no max range, all four finite, inside the
// key range, no coordinate below kTinyCoordinate but 0 and farther than kMinRayLength from the
// origin along some axis (so that no ray of theirs is degenerate). Keys by coordToKeyChecked's
// expression (floor(1 / resolution * coord) in double),
// the box kept in lanes; any other group of four goes to prepare_points, so the rays, their
// order and the counts are the scalar loop's.
__attribute__((target("avx2"))) void prepare_points_avx2(const octomap::point3d& origin,
                                                         const octomap::OcTreeKey& origin_key,
                                                         std::span<const octomap::point3d> points, double max_range,
                                                         double resolution, PreparedChunk& out) {
  static_assert(sizeof(octomap::point3d) == 12);
  const size_t groups = max_range < 0.0 ? points.size() / 4 : 0;
  const __m256d factor = _mm256_set1_pd(1.0 / resolution), low = _mm256_set1_pd(-32768.0),
                high = _mm256_set1_pd(32768.0);
  const __m128i max_val = _mm_set1_epi32(32768);
  const __m128 sign_bit = _mm_set1_ps(-0.0f), near = _mm_set1_ps(kMinRayLength), tiny = _mm_set1_ps(kTinyCoordinate);
  const __m128 o[3] = {_mm_set1_ps(origin.x()), _mm_set1_ps(origin.y()), _mm_set1_ps(origin.z())};
  __m128i lo[3], hi[3];
  for (int i = 0; i < 3; ++i) lo[i] = _mm_set1_epi32(65536), hi[i] = _mm_set1_epi32(-1);
  size_t n = out.ends.size();
  out.ends.resize(n + 4 * groups);  // written below, cut to the rays made
  for (size_t g = 0; g < groups; ++g) {
    const float* f = &points[4 * g](0);
    const __m128 a = _mm_loadu_ps(f), b = _mm_loadu_ps(f + 4), c = _mm_loadu_ps(f + 8);
    // a = x0 y0 z0 x1, b = y1 z1 x2 y2, c = z2 x3 y3 z3
    const __m128 x = _mm_shuffle_ps(_mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 3, 0, 0)),
                                    _mm_shuffle_ps(b, c, _MM_SHUFFLE(1, 1, 2, 2)), _MM_SHUFFLE(2, 0, 2, 0));
    const __m128 y = _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 0, 1, 1)),
                                    _mm_shuffle_ps(b, c, _MM_SHUFFLE(2, 2, 3, 3)), _MM_SHUFFLE(2, 0, 2, 0));
    const __m128 z = _mm_shuffle_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 1, 2, 2)),
                                    _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 0, 0)), _MM_SHUFFLE(2, 0, 2, 0));
    const __m128 v[3] = {x, y, z};
    // -0 reads as +0 (read_tiny_as_zero); lanes with a tiny nonzero coordinate go to the
    // point-by-point rules below, which count them.
    __m128 r[3];
    for (int i = 0; i < 3; ++i) r[i] = _mm_and_ps(v[i], _mm_cmpneq_ps(v[i], _mm_setzero_ps()));
    __m128i key[3];
    __m256d ok = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
    __m128 away = _mm_setzero_ps();  // lanes farther than kMinRayLength from the origin along some axis
    __m128 read_as_is = _mm_castsi128_ps(_mm_set1_epi32(-1));  // lanes without a tiny nonzero coordinate
    for (int i = 0; i < 3; ++i) {
      away = _mm_or_ps(away, _mm_cmpgt_ps(_mm_andnot_ps(sign_bit, _mm_sub_ps(v[i], o[i])), near));
      const __m128 tiny_lane =
          _mm_and_ps(_mm_cmplt_ps(_mm_andnot_ps(sign_bit, v[i]), tiny), _mm_cmpneq_ps(v[i], _mm_setzero_ps()));
      read_as_is = _mm_andnot_ps(tiny_lane, read_as_is);
    }
    ok = _mm256_and_pd(ok, _mm256_castsi256_pd(_mm256_cvtepi32_epi64(_mm_castps_si128(_mm_and_ps(away, read_as_is)))));
    for (int i = 0; i < 3; ++i) {
      const __m256d scaled = _mm256_mul_pd(factor, _mm256_cvtps_pd(v[i]));
      // scaled >= -32768 and < 32768 (false for NaN and inf: the finiteness test too).
      ok = _mm256_and_pd(
          ok, _mm256_and_pd(_mm256_cmp_pd(scaled, low, _CMP_GE_OQ), _mm256_cmp_pd(scaled, high, _CMP_LT_OQ)));
      key[i] = _mm_add_epi32(_mm256_cvttpd_epi32(_mm256_round_pd(scaled, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC)),
                             max_val);
    }
    if (_mm256_movemask_pd(ok) != 15) {
      octomap::OcTreeKey k;
      for (size_t j = 4 * g; j < 4 * g + 4; ++j)
        if (prepare_point(origin, origin_key, points[j], max_range, resolution, out.report, out.ends[n], k))
          out.keys.include(k), ++n;
      continue;
    }
    for (int i = 0; i < 3; ++i) lo[i] = _mm_min_epi32(lo[i], key[i]), hi[i] = _mm_max_epi32(hi[i], key[i]);
    __m128 r0 = r[0], r1 = r[1], r2 = r[2], r3 = _mm_castsi128_ps(_mm_set1_epi32(kRayEndOccupied));
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
    float* dst = &out.ends[n].x;
    _mm_storeu_ps(dst, r0), _mm_storeu_ps(dst + 4, r1), _mm_storeu_ps(dst + 8, r2), _mm_storeu_ps(dst + 12, r3);
    n += 4;
  }
  out.ends.resize(n);
  alignas(16) int32_t l[3][4], h[3][4];
  for (int i = 0; i < 3; ++i) _mm_store_si128((__m128i*)l[i], lo[i]), _mm_store_si128((__m128i*)h[i], hi[i]);
  for (int j = 0; j < 4; ++j)
    if (h[0][j] >= 0) {
      out.keys.include(octomap::OcTreeKey(l[0][j], l[1][j], l[2][j]));
      out.keys.include(octomap::OcTreeKey(h[0][j], h[1][j], h[2][j]));
    }
  prepare_points(origin, origin_key, points.subspan(4 * groups), max_range, resolution, out);
}
#endif

void prepare_chunk(const octomap::point3d& origin, const octomap::OcTreeKey& origin_key,
                   std::span<const octomap::point3d> points, double max_range, double resolution, bool simd,
                   PreparedChunk& out) {
  out.ends.reserve(points.size());
#if defined(__x86_64__)
  if (simd && __builtin_cpu_supports("avx2"))
    return prepare_points_avx2(origin, origin_key, points, max_range, resolution, out);
#endif
  prepare_points(origin, origin_key, points, max_range, resolution, out);
}

}  // namespace

uint64_t tiny_as_sent_only(std::span<const float> xyz, std::span<const octomap::point3d> world) {
  uint64_t n = 0;
  for (size_t i = 0; i < world.size(); ++i) {
    const octomap::point3d sent(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    n += finite(sent) && finite(world[i]) && has_tiny_coordinate(sent) && !has_tiny_coordinate(world[i]);
  }
  return n;
}

bool prepare_origin(const octomap::point3d& given, double resolution, RayBatch& batch, PrepareReport& report) {
  const octomap::point3d origin = read_tiny_as_zero(given);
  batch.origin = origin;
  batch.resolution = resolution;
  if (!finite(origin) || !coord_to_key_checked(origin, resolution, batch.origin_key)) {
    report.origin_ok = false;
    report.error = "sensor origin is not finite or lies outside the map's key range";
    return false;
  }
  batch.keys.include(batch.origin_key);
  return true;
}

RayBatch prepare_scan(const octomap::point3d& origin, std::span<const octomap::point3d> points, double max_range,
                      double resolution, PrepareReport& report, unsigned threads, bool simd) {
  RayBatch batch;
  report.points_in += points.size();
  if (!prepare_origin(origin, resolution, batch, report)) return batch;
  const octomap::point3d& read_origin = batch.origin;  // the contract's reading (read_tiny_as_zero)
  // Each point is prepared on its own, so contiguous chunks on several threads, joined in
  // order, give exactly the single-threaded batch (same rays, same order).
  constexpr size_t kMinPointsPerThread = 32768;
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = unsigned(std::min<size_t>(threads, std::max<size_t>(1, points.size() / kMinPointsPerThread)));
  std::vector<PreparedChunk> chunks(threads);
  auto run = [&](unsigned t) {
    const size_t begin = points.size() * t / threads, end = points.size() * (t + 1) / threads;
    prepare_chunk(read_origin, batch.origin_key, points.subspan(begin, end - begin), max_range, resolution, simd,
                  chunks[t]);
  };
  {
    std::vector<std::jthread> pool;
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(run, t);
    run(0);
  }
  if (threads == 1) {
    batch.ends = std::move(chunks[0].ends);
  } else {
    size_t total = 0;
    for (const auto& c : chunks) total += c.ends.size();
    batch.ends.reserve(total);
  }
  for (auto& c : chunks) {
    if (threads > 1) batch.ends.insert(batch.ends.end(), c.ends.begin(), c.ends.end());
    if (!c.keys.empty()) {
      batch.keys.include(octomap::OcTreeKey(c.keys.lo[0], c.keys.lo[1], c.keys.lo[2]));
      batch.keys.include(octomap::OcTreeKey(c.keys.hi[0], c.keys.hi[1], c.keys.hi[2]));
    }
    report.nonfinite += c.report.nonfinite;
    report.out_of_range += c.report.out_of_range;
    report.cut_at_max_range += c.report.cut_at_max_range;
    report.degenerate += c.report.degenerate;
    report.read_as_zero += c.report.read_as_zero;
  }
  report.rays += batch.ends.size();
  batch.keys_hold_ends = true;
  return batch;
}

}  // namespace ort
