#include "core/window_walk_avx2.h"

#include <limits>
#include <stdexcept>

#include "core/prepare_scan.h"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace ort {

#if defined(__x86_64__)

bool cpu_has_avx2() { return __builtin_cpu_supports("avx2"); }

namespace {

// Lane state in memory: read into registers after a lane is refilled, written back before.
struct alignas(32) Lanes {
  double tx[4], ty[4], tz[4], dx[4], dy[4], dz[4], length[4];
  int64_t x[4], y[4], z[4], sx[4], sy[4], sz[4], x_out[4], y_out[4], z_out[4], ex[4], ey[4], ez[4], active[4];
};

// The DDA's start (octomap_ray_start) of up to four rays, computed in AVX2 lanes with the
// same IEEE operations in the same order (float difference, float squared norm, double sqrt
// cast to float, float division, double border/difference/division), so bit for bit the
// scalar start: the start's seven divisions a ray were a quarter of the walk's time.
struct alignas(32) StartBlock {
  double t_max[3][4], t_delta[3][4], length[4];
  int64_t step[3][4], end_key[3][4];
  int count = 0, next = 0;
};

// Feeds the lanes ray after ray; marks what a ray needs beyond its walk (its measured end,
// its origin voxel) as it is taken. Rays inside one voxel only mark their end.
class RayFeed {
 public:
  RayFeed(const RayBatch& b, size_t begin, size_t end, const BrickLayout& layout, double res, GridMarker& m)
      : b_(b), next_(begin), end_(end), layout_(layout), res_(res), marker_(m) {
    constexpr int kTreeMaxVal = 32768;
    const KeyBox& w = layout.window();
    for (int i = 0; i < 3; ++i) {
      origin_[i] = b.origin_key[i] - w.lo[i], extent_[i] = layout.extent(i);
      // octomap_ray_start's voxel border for a positive and a negative step (the origin key is
      // the same for every ray of the batch).
      const double centre = (double((int)b.origin_key[i] - kTreeMaxVal) + 0.5) * res;
      border_up_[i] = centre + (float)(1 * res * 0.5);
      border_down_[i] = centre + (float)(-1 * res * 0.5);
    }
    origin_index_ = layout.x_offsets()[origin_[0]] + layout.y_offsets()[origin_[1]] + layout.z_offsets()[origin_[2]];
  }

  // Loads the next ray that walks at least one step into lane l; false (lane idle) when none is left.
  __attribute__((target("avx2"))) bool load(Lanes& L, int l) {
    if (block_.next == block_.count && !fill_block()) {
      L.active[l] = 0;
      return false;
    }
    const int r = block_.next++;
    L.tx[l] = block_.t_max[0][r], L.ty[l] = block_.t_max[1][r], L.tz[l] = block_.t_max[2][r];
    L.dx[l] = block_.t_delta[0][r], L.dy[l] = block_.t_delta[1][r], L.dz[l] = block_.t_delta[2][r];
    L.length[l] = block_.length[r];
    L.x[l] = origin_[0], L.y[l] = origin_[1], L.z[l] = origin_[2];
    L.sx[l] = block_.step[0][r], L.sy[l] = block_.step[1][r], L.sz[l] = block_.step[2][r];
    L.x_out[l] = block_.step[0][r] > 0 ? extent_[0] : -1;
    L.y_out[l] = block_.step[1][r] > 0 ? extent_[1] : -1;
    L.z_out[l] = block_.step[2][r] > 0 ? extent_[2] : -1;
    L.ex[l] = block_.end_key[0][r], L.ey[l] = block_.end_key[1][r], L.ez[l] = block_.end_key[2][r];
    L.active[l] = -1;
    return true;
  }

 private:
  // Takes up to four rays that leave the origin voxel and computes their starts.
  __attribute__((target("avx2"))) bool fill_block() {
    alignas(16) float ends[3][4];
    int n = 0;
    const KeyBox& w = layout_.window();
    while (n < 4 && next_ < end_) {
      const RayEnd& e = b_.ends[next_++];
      octomap::OcTreeKey end_key;
      coord_to_key_checked(octomap::point3d(e.x, e.y, e.z), res_, end_key);  // prepare_scan kept only in-range ends
      if ((e.flags & kRayEndOccupied) && layout_.contains(end_key)) marker_.mark(layout_.index(end_key), kStateOccupied);
      if (end_key == b_.origin_key) continue;
      marker_.mark(origin_index_, kStateFree);
      ends[0][n] = e.x, ends[1][n] = e.y, ends[2][n] = e.z;
      for (int i = 0; i < 3; ++i) block_.end_key[i][n] = end_key[i] - w.lo[i];
      ++n;
    }
    for (int k = n; k < 4; ++k)  // unused lanes repeat a real ray (no division by zero)
      for (int i = 0; i < 3; ++i) ends[i][k] = n ? ends[i][0] : b_.origin(i) + 1.0f;
    block_.count = n, block_.next = 0;
    if (n == 0) return false;
    compute_starts(ends);
    return true;
  }

  __attribute__((target("avx2"))) void compute_starts(const float (&ends)[3][4]) {
    __m128 d[3];
    for (int i = 0; i < 3; ++i) d[i] = _mm_sub_ps(_mm_load_ps(ends[i]), _mm_set1_ps(b_.origin(i)));
    // norm_sq in float as (x*x + y*y) + z*z, sqrt in double, cast to float.
    const __m128 norm_sq = _mm_add_ps(_mm_add_ps(_mm_mul_ps(d[0], d[0]), _mm_mul_ps(d[1], d[1])), _mm_mul_ps(d[2], d[2]));
    const __m128 length = _mm256_cvtpd_ps(_mm256_sqrt_pd(_mm256_cvtps_pd(norm_sq)));
    _mm256_store_pd(block_.length, _mm256_cvtps_pd(length));
    const __m256d max = _mm256_set1_pd(std::numeric_limits<double>::max());
    const __m256d res = _mm256_set1_pd(res_);
    const __m128 sign = _mm_set1_ps(-0.0f);
    for (int i = 0; i < 3; ++i) {
      const __m128 dir = _mm_div_ps(d[i], length);  // direction /= length
      const __m128 up = _mm_cmpgt_ps(dir, _mm_setzero_ps()), down = _mm_cmplt_ps(dir, _mm_setzero_ps());
      const __m256i up64 = _mm256_cvtepi32_epi64(_mm_castps_si128(up));
      const __m256i down64 = _mm256_cvtepi32_epi64(_mm_castps_si128(down));
      // step: 1, -1 or 0 (the masks are all ones: -1 & 1 = 1, -1 = -1).
      const __m256i step = _mm256_or_si256(_mm256_and_si256(up64, _mm256_set1_epi64x(1)), down64);
      _mm256_store_si256((__m256i*)block_.step[i], step);
      const __m256d moving = _mm256_castsi256_pd(_mm256_or_si256(up64, down64));
      const __m256d border = _mm256_blendv_pd(_mm256_set1_pd(border_down_[i]), _mm256_set1_pd(border_up_[i]),
                                              _mm256_castsi256_pd(up64));
      const __m256d dir64 = _mm256_cvtps_pd(dir);
      const __m256d t_max = _mm256_div_pd(_mm256_sub_pd(border, _mm256_set1_pd(double(b_.origin(i)))), dir64);
      const __m256d t_delta = _mm256_div_pd(res, _mm256_cvtps_pd(_mm_andnot_ps(sign, dir)));  // fabs in float
      _mm256_store_pd(block_.t_max[i], _mm256_blendv_pd(max, t_max, moving));
      _mm256_store_pd(block_.t_delta[i], _mm256_blendv_pd(max, t_delta, moving));
    }
  }

  const RayBatch& b_;
  size_t next_, end_;
  const BrickLayout& layout_;
  double res_;
  GridMarker& marker_;
  int64_t origin_[3], extent_[3];
  double border_up_[3], border_down_[3];
  uint32_t origin_index_;
  StartBlock block_;
};

// Free marks found unset wait in a buffer of this many indices.
constexpr int kPending = 64;

// For each mask of 4 lanes, the permutation that moves the low 32 bits of each set lane's
// 64-bit value to the front, in lane order (_mm256_permutevar8x32_epi32's control).
struct PackTable {
  alignas(32) int32_t control[16][8];
};
constexpr PackTable kPackLanes = [] {
  PackTable table{};
  for (int mask = 0; mask < 16; ++mask)
    for (int lane = 0, n = 0; lane < 4; ++lane)
      if (mask >> lane & 1) table.control[mask][n++] = 2 * lane;
  return table;
}();

// BrickLayout::index in lanes: (key - window.lo) per axis -> the voxel's index in the grid
// (bits 0-1 x & 3, 2-3 y & 3, 4 x >> 2 & 1, 5 y >> 2 & 1, 6-7 z & 3, then whole bricks).
__attribute__((target("avx2"))) inline __m256i brick_index(__m256i x, __m256i y, __m256i z, __m256i brick_row,
                                                          __m256i brick_layer) {
  const __m256i three = _mm256_set1_epi64x(3), one = _mm256_set1_epi64x(1);
  const __m256i in_x = _mm256_or_si256(_mm256_and_si256(x, three),
                                       _mm256_slli_epi64(_mm256_and_si256(_mm256_srli_epi64(x, 2), one), 4));
  const __m256i in_y = _mm256_or_si256(_mm256_slli_epi64(_mm256_and_si256(y, three), 2),
                                       _mm256_slli_epi64(_mm256_and_si256(_mm256_srli_epi64(y, 2), one), 5));
  const __m256i in_z = _mm256_slli_epi64(_mm256_and_si256(z, three), 6);
  const __m256i bricks = _mm256_add_epi64(
      _mm256_add_epi64(_mm256_slli_epi64(_mm256_srli_epi64(x, 3), 8), _mm256_mul_epu32(_mm256_srli_epi64(y, 3), brick_row)),
      _mm256_mul_epu32(_mm256_srli_epi64(z, 2), brick_layer));
  return _mm256_add_epi64(_mm256_or_si256(_mm256_or_si256(in_x, in_y), in_z), bricks);
}

}  // namespace

__attribute__((target("avx2"))) void walk_rays_avx2(const RayBatch& b, size_t begin, size_t end,
                                                     const BrickLayout& layout, double resolution,
                                                     GridMarker& marker) {
  if (!layout.contains(b.origin_key)) throw std::logic_error("walk_rays_avx2: the origin lies outside the window");
  const __m256i brick_row = _mm256_set1_epi64x(layout.brick_row()), brick_layer = _mm256_set1_epi64x(layout.brick_layer());
  const __m256i free_bit = _mm256_set1_epi64x(kStateFree), fifteen = _mm256_set1_epi64x(15);
  const long long* grid = reinterpret_cast<const long long*>(marker.grid);
  RayFeed feed(b, begin, end, layout, resolution, marker);
  Lanes L{};
  int live = 0;
  for (int l = 0; l < 4; ++l) live += feed.load(L, l);
  const __m256i ones = _mm256_set1_epi64x(-1);
  alignas(32) uint32_t pending[kPending];
  int n_pending = 0;
  while (live > 0) {
    __m256d tx = _mm256_load_pd(L.tx), ty = _mm256_load_pd(L.ty), tz = _mm256_load_pd(L.tz);
    const __m256d dx = _mm256_load_pd(L.dx), dy = _mm256_load_pd(L.dy), dz = _mm256_load_pd(L.dz);
    const __m256d length = _mm256_load_pd(L.length);
    __m256i x = _mm256_load_si256((const __m256i*)L.x), y = _mm256_load_si256((const __m256i*)L.y),
            z = _mm256_load_si256((const __m256i*)L.z);
    const __m256i sx = _mm256_load_si256((const __m256i*)L.sx), sy = _mm256_load_si256((const __m256i*)L.sy),
                  sz = _mm256_load_si256((const __m256i*)L.sz);
    const __m256i x_out = _mm256_load_si256((const __m256i*)L.x_out),
                  y_out = _mm256_load_si256((const __m256i*)L.y_out),
                  z_out = _mm256_load_si256((const __m256i*)L.z_out);
    const __m256i ex = _mm256_load_si256((const __m256i*)L.ex), ey = _mm256_load_si256((const __m256i*)L.ey),
                  ez = _mm256_load_si256((const __m256i*)L.ez);
    const __m256i active = _mm256_load_si256((const __m256i*)L.active);
    while (true) {
      // The scalar walk: x if tx < ty and tx < tz; else y if !(tx < ty) and ty < tz; else z.
      const __m256d x_lt_y = _mm256_cmp_pd(tx, ty, _CMP_LT_OQ), x_lt_z = _mm256_cmp_pd(tx, tz, _CMP_LT_OQ),
                    y_lt_z = _mm256_cmp_pd(ty, tz, _CMP_LT_OQ);
      const __m256d step_x = _mm256_and_pd(x_lt_y, x_lt_z), step_y = _mm256_andnot_pd(x_lt_y, y_lt_z);
      const __m256d step_z = _mm256_andnot_pd(_mm256_or_pd(step_x, step_y), _mm256_castsi256_pd(ones));
      x = _mm256_add_epi64(x, _mm256_and_si256(_mm256_castpd_si256(step_x), sx));
      y = _mm256_add_epi64(y, _mm256_and_si256(_mm256_castpd_si256(step_y), sy));
      z = _mm256_add_epi64(z, _mm256_and_si256(_mm256_castpd_si256(step_z), sz));
      tx = _mm256_add_pd(tx, _mm256_and_pd(step_x, dx));  // + 0.0 in the other lanes: unchanged
      ty = _mm256_add_pd(ty, _mm256_and_pd(step_y, dy));
      tz = _mm256_add_pd(tz, _mm256_and_pd(step_z, dz));
      // Stops: out of the window along the step, at the end voxel, past the length.
      const __m256i left = _mm256_or_si256(_mm256_or_si256(_mm256_cmpeq_epi64(x, x_out), _mm256_cmpeq_epi64(y, y_out)),
                                           _mm256_cmpeq_epi64(z, z_out));
      const __m256i at_end = _mm256_and_si256(_mm256_and_si256(_mm256_cmpeq_epi64(x, ex), _mm256_cmpeq_epi64(y, ey)),
                                              _mm256_cmpeq_epi64(z, ez));
      // std::min(a, b) is (b < a ? b : a), which _mm256_min_pd(b, a) computes.
      const __m256d dist = _mm256_min_pd(tz, _mm256_min_pd(ty, tx));
      const __m256i past = _mm256_castpd_si256(_mm256_cmp_pd(dist, length, _CMP_GT_OQ));
      const __m256i done = _mm256_and_si256(_mm256_or_si256(_mm256_or_si256(left, at_end), past), active);
      const __m256i visiting = _mm256_andnot_si256(done, active);
      // The mark's test in lanes: the voxel index as BrickLayout's tables give it, the grid
      // word of each visiting lane gathered (word 0 for the others), and only the lanes whose
      // free bit is not set yet go on to the scalar mark (most visits near the sensor find it set).
      const __m256i index = brick_index(x, y, z, brick_row, brick_layer);
      const __m256i word = _mm256_and_si256(_mm256_srli_epi64(index, 4), visiting);
      const __m256i bit = _mm256_sllv_epi64(free_bit, _mm256_slli_epi64(_mm256_and_si256(index, fifteen), 1));
      const __m256i got = _mm256_i64gather_epi64(grid, word, 4);  // the word and the next: the low 32 bits count
      const __m256i is_set = _mm256_cmpeq_epi64(_mm256_and_si256(got, bit), bit);
      const int unmarked = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_andnot_si256(is_set, visiting)));
      // Their indices go to `pending` without a branch (a branch on the gathered bits
      // mispredicts on most visits away from the sensor); marked (tested again) when it fills.
      const __m256i packed = _mm256_permutevar8x32_epi32(index, _mm256_load_si256(reinterpret_cast<const __m256i*>(kPackLanes.control[unmarked])));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(pending + n_pending), _mm256_castsi256_si128(packed));
      n_pending += __builtin_popcount(unsigned(unmarked));
      if (n_pending > kPending - 4) {
        marker.mark_all(pending, n_pending, kStateFree);
        n_pending = 0;
      }
      const int finished = _mm256_movemask_pd(_mm256_castsi256_pd(done));
      if (!finished) continue;
      _mm256_store_pd(L.tx, tx), _mm256_store_pd(L.ty, ty), _mm256_store_pd(L.tz, tz);
      _mm256_store_si256((__m256i*)L.x, x), _mm256_store_si256((__m256i*)L.y, y), _mm256_store_si256((__m256i*)L.z, z);
      for (int bits = finished; bits; bits &= bits - 1) live -= !feed.load(L, __builtin_ctz(unsigned(bits)));
      break;  // reload the lanes
    }
  }
  marker.mark_all(pending, n_pending, kStateFree);
}

#else

bool cpu_has_avx2() { return false; }

void walk_rays_avx2(const RayBatch&, size_t, size_t, const BrickLayout&, double, GridMarker&) {
  throw std::logic_error("walk_rays_avx2: not an x86-64 build");
}

#endif

}  // namespace ort
