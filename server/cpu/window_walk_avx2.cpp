#include "cpu/window_walk_avx2.h"

#include <algorithm>
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
// (bits 0-2 x & 7, 3-5 y & 7, 6-7 z & 3, then whole bricks).
__attribute__((target("avx2"))) inline __m256i brick_index(__m256i x, __m256i y, __m256i z, __m256i brick_row,
                                                           __m256i brick_layer) {
  const __m256i seven = _mm256_set1_epi64x(7), three = _mm256_set1_epi64x(3);
  const __m256i in_brick =
      _mm256_or_si256(_mm256_or_si256(_mm256_and_si256(x, seven), _mm256_slli_epi64(_mm256_and_si256(y, seven), 3)),
                      _mm256_slli_epi64(_mm256_and_si256(z, three), 6));
  const __m256i bricks = _mm256_add_epi64(_mm256_add_epi64(_mm256_slli_epi64(_mm256_srli_epi64(x, 3), 8),
                                                           _mm256_mul_epu32(_mm256_srli_epi64(y, 3), brick_row)),
                                          _mm256_mul_epu32(_mm256_srli_epi64(z, 2), brick_layer));
  return _mm256_add_epi64(in_brick, bricks);
}

// The DDA's start (octomap_ray_start) of up to four rays, computed in AVX2 lanes with the
// same IEEE operations in the same order (float difference, float squared norm, double sqrt
// cast to float, float division, double border/difference/division), so bit for bit the
// scalar start: the start's seven divisions a ray were a quarter of the walk's time.
struct alignas(32) StartBlock {
  double t_max[3][4], t_delta[3][4], length[4];
  int64_t step[3][4];
  int64_t index_step[3][4];  // row-by-row layouts: the index's change for a step along each axis
  int64_t end_index[4];      // the end voxel's index in the grid; -1 (no voxel's) where the end lies outside the window
  int64_t out[3][4];         // the first coordinate (key - window.lo) outside the window along the step
  int order[4];              // the rays (places above) that leave the origin voxel; the others are unused
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
    for (int i = 0; i < 3; ++i) lo_minus_max_[i] = int64_t(w.lo[i]) - kTreeMaxVal;
    brick_row_ = layout.brick_row(), brick_layer_ = layout.brick_layer();
    rows_ = layout.rows(), stride_[0] = 1, stride_[1] = layout.y_stride(), stride_[2] = layout.z_stride();
    origin_index_ = layout.x_offsets()[origin_[0]] + layout.y_offsets()[origin_[1]] + layout.z_offsets()[origin_[2]];
    origin_index64_ = origin_index_;
  }

  // The next ray that walks at least one step: its place in block(); -1 when none is left.
  __attribute__((target("avx2"))) int take() {
    if (block_.next == block_.count && !fill_block()) return -1;
    return block_.order[block_.next++];
  }
  const StartBlock& block() const { return block_; }
  const int64_t* origin() const { return origin_; }
  const int64_t& origin_index() const { return origin_index64_; }
  // Sets the measured ends still waiting (call when no ray is left).
  void finish() {
    marker_.mark_all(occupied_, n_occupied_, kStateOccupied);
    n_occupied_ = 0;
  }

 private:
  // Takes the next four rays (fewer at the batch's end): their end keys in lanes (OctoMap's
  // coordToKeyChecked: floor(1 / resolution * coord) in double), their measured ends queued
  // as occupied marks, and the starts of those that leave the origin voxel. False when no
  // ray is left that leaves it.
  __attribute__((target("avx2"))) bool fill_block() {
    while (next_ < end_) {
      const size_t n = std::min<size_t>(4, end_ - next_);
      __m128 e[4];  // x, y, z, flags of four rays
      for (size_t j = 0; j < 4; ++j) e[j] = _mm_loadu_ps(&b_.ends[next_ + std::min(j, n - 1)].x);
      next_ += n;
      _MM_TRANSPOSE4_PS(e[0], e[1], e[2], e[3]);
      __m256i key[3];  // key - window.lo
      __m256i inside = _mm256_cmpgt_epi64(_mm256_set1_epi64x(int64_t(n)), _mm256_setr_epi64x(0, 1, 2, 3));
      __m256i at_origin = inside;
      for (int i = 0; i < 3; ++i) {
        const __m256d scaled = _mm256_mul_pd(_mm256_set1_pd(1.0 / res_), _mm256_cvtps_pd(e[i]));
        const __m128i floored = _mm256_cvttpd_epi32(_mm256_round_pd(scaled, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC));
        key[i] = _mm256_sub_epi64(_mm256_cvtepi32_epi64(floored), _mm256_set1_epi64x(lo_minus_max_[i]));
        inside =
            _mm256_and_si256(inside, _mm256_andnot_si256(_mm256_cmpgt_epi64(_mm256_setzero_si256(), key[i]),
                                                         _mm256_cmpgt_epi64(_mm256_set1_epi64x(extent_[i]), key[i])));
        at_origin = _mm256_and_si256(at_origin, _mm256_cmpeq_epi64(key[i], _mm256_set1_epi64x(origin_[i])));
      }
      const __m256i occupied = _mm256_cvtepi32_epi64(_mm_castps_si128(
          _mm_cmpneq_ps(_mm_and_ps(e[3], _mm_castsi128_ps(_mm_set1_epi32(kRayEndOccupied))), _mm_setzero_ps())));
      const __m256i index =
          rows_ ? _mm256_add_epi64(key[0], _mm256_add_epi64(_mm256_mul_epu32(key[1], _mm256_set1_epi64x(stride_[1])),
                                                            _mm256_mul_epu32(key[2], _mm256_set1_epi64x(stride_[2]))))
                : brick_index(key[0], key[1], key[2], _mm256_set1_epi64x(brick_row_), _mm256_set1_epi64x(brick_layer_));
      queue_occupied(_mm256_and_si256(occupied, inside), index);
      _mm256_store_si256(reinterpret_cast<__m256i*>(block_.end_index),
                         _mm256_or_si256(index, _mm256_xor_si256(inside, _mm256_set1_epi64x(-1))));
      const __m256i valid = _mm256_cmpgt_epi64(_mm256_set1_epi64x(int64_t(n)), _mm256_setr_epi64x(0, 1, 2, 3));
      const int walks = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_andnot_si256(at_origin, valid)));
      if (!walks) continue;
      if (!origin_marked_) marker_.mark(origin_index_, kStateFree), origin_marked_ = true;
      block_.count = 0, block_.next = 0;
      for (int bits = walks; bits; bits &= bits - 1) block_.order[block_.count++] = __builtin_ctz(unsigned(bits));
      // Rays that do not walk take a direction that cannot divide by zero; their starts go unused.
      const __m128 unused = _mm_castsi128_ps(
          _mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(walks), _mm_setr_epi32(1, 2, 4, 8)), _mm_setzero_si128()));
      alignas(16) float ends[3][4];
      for (int i = 0; i < 3; ++i) _mm_store_ps(ends[i], _mm_blendv_ps(e[i], _mm_set1_ps(b_.origin(i) + 1.0f), unused));
      compute_starts(ends);
      return true;
    }
    return false;
  }

  // Queues the occupied marks of the lanes in `mask`, set in batches (as the walk's free marks).
  __attribute__((target("avx2"))) void queue_occupied(__m256i mask, __m256i index) {
    const int lanes = _mm256_movemask_pd(_mm256_castsi256_pd(mask));
    const __m256i packed = _mm256_permutevar8x32_epi32(
        index, _mm256_load_si256(reinterpret_cast<const __m256i*>(kPackLanes.control[lanes])));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(occupied_ + n_occupied_), _mm256_castsi256_si128(packed));
    n_occupied_ += __builtin_popcount(unsigned(lanes));
    if (n_occupied_ > kPending - 4) finish();
  }

  __attribute__((target("avx2"))) void compute_starts(const float (&ends)[3][4]) {
    __m128 d[3];
    for (int i = 0; i < 3; ++i) d[i] = _mm_sub_ps(_mm_load_ps(ends[i]), _mm_set1_ps(b_.origin(i)));
    // norm_sq in float as (x*x + y*y) + z*z, sqrt in double, cast to float.
    const __m128 norm_sq =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(d[0], d[0]), _mm_mul_ps(d[1], d[1])), _mm_mul_ps(d[2], d[2]));
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
      _mm256_store_si256((__m256i*)block_.index_step[i], _mm256_mul_epi32(step, _mm256_set1_epi64x(stride_[i])));
      _mm256_store_si256((__m256i*)block_.out[i],
                         _mm256_blendv_epi8(_mm256_set1_epi64x(-1), _mm256_set1_epi64x(extent_[i]), up64));
      const __m256d moving = _mm256_castsi256_pd(_mm256_or_si256(up64, down64));
      const __m256d border =
          _mm256_blendv_pd(_mm256_set1_pd(border_down_[i]), _mm256_set1_pd(border_up_[i]), _mm256_castsi256_pd(up64));
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
  bool origin_marked_ = false;
  int64_t lo_minus_max_[3];  // window.lo - 32768: key - window.lo = floor(...) - this
  uint32_t brick_row_, brick_layer_;
  bool rows_;
  int64_t stride_[3];  // row by row: the index's change for +1 along x, y, z
  int64_t origin_index64_;
  alignas(16) uint32_t occupied_[kPending];
  int n_occupied_ = 0;
  StartBlock block_;
};

// The four lanes' DDA state, kept in registers; a finished lane takes its next ray by
// broadcast and blend (scalar stores into memory read back as vectors stall the walk).
struct LaneState {
  __m256d tx, ty, tz, dx, dy, dz, length;
  __m256i x, y, z, sx, sy, sz, x_out, y_out, z_out, end, active;
  __m256i index, index_dx, index_dy, index_dz;  // row-by-row layouts: the index kept step by step

  __attribute__((target("avx2"), always_inline)) static __m256d put(__m256d v, const double& from, __m256d lane) {
    return _mm256_blendv_pd(v, _mm256_broadcast_sd(&from), lane);
  }
  __attribute__((target("avx2"), always_inline)) static __m256i put(__m256i v, const int64_t& from, __m256d lane) {
    return _mm256_castpd_si256(
        _mm256_blendv_pd(_mm256_castsi256_pd(v), _mm256_broadcast_sd(reinterpret_cast<const double*>(&from)), lane));
  }
  // Lane `lane` (all ones there, zeros elsewhere) starts ray r of block b at the origin voxel.
  __attribute__((target("avx2"), always_inline)) void start(const StartBlock& b, int r, const int64_t* origin,
                                                            const int64_t& origin_index, __m256d lane) {
    tx = put(tx, b.t_max[0][r], lane), ty = put(ty, b.t_max[1][r], lane), tz = put(tz, b.t_max[2][r], lane);
    dx = put(dx, b.t_delta[0][r], lane), dy = put(dy, b.t_delta[1][r], lane), dz = put(dz, b.t_delta[2][r], lane);
    length = put(length, b.length[r], lane);
    x = put(x, origin[0], lane), y = put(y, origin[1], lane), z = put(z, origin[2], lane);
    sx = put(sx, b.step[0][r], lane), sy = put(sy, b.step[1][r], lane), sz = put(sz, b.step[2][r], lane);
    x_out = put(x_out, b.out[0][r], lane), y_out = put(y_out, b.out[1][r], lane), z_out = put(z_out, b.out[2][r], lane);
    end = put(end, b.end_index[r], lane);
    index = put(index, origin_index, lane);
    index_dx = put(index_dx, b.index_step[0][r], lane), index_dy = put(index_dy, b.index_step[1][r], lane);
    index_dz = put(index_dz, b.index_step[2][r], lane);
    active = _mm256_or_si256(active, _mm256_castpd_si256(lane));
  }
  __attribute__((target("avx2"), always_inline)) void stop(__m256d lane) {
    active = _mm256_andnot_si256(_mm256_castpd_si256(lane), active);
  }
};

// The walk in lanes; kRows: the layout is row by row (the index kept with one add a step),
// else bricks (the index from the keys, BrickLayout::index as bit operations). kExits: a ray
// may leave the window, so each lane keeps its key and stops where it leaves; false (rows
// only, rays_stay_inside) drops the keys and that test, a fifth of the step's operations.
template <bool kRows, bool kExits>
__attribute__((target("avx2"))) void walk_lanes(const RayBatch& b, size_t begin, size_t end, const BrickLayout& layout,
                                                double resolution, GridMarker& marker) {
  const __m256i brick_row = _mm256_set1_epi64x(layout.brick_row()),
                brick_layer = _mm256_set1_epi64x(layout.brick_layer());
  const __m256i free_bit = _mm256_set1_epi64x(kStateFree), fifteen = _mm256_set1_epi64x(15);
  const long long* grid = reinterpret_cast<const long long*>(marker.grid);
  RayFeed feed(b, begin, end, layout, resolution, marker);
  const int64_t* origin = feed.origin();
  const __m256d lane_masks[4] = {
      _mm256_castsi256_pd(_mm256_setr_epi64x(-1, 0, 0, 0)), _mm256_castsi256_pd(_mm256_setr_epi64x(0, -1, 0, 0)),
      _mm256_castsi256_pd(_mm256_setr_epi64x(0, 0, -1, 0)), _mm256_castsi256_pd(_mm256_setr_epi64x(0, 0, 0, -1))};
  LaneState L{};
  int live = 0;
  for (int l = 0; l < 4; ++l) {
    const int r = feed.take();
    if (r < 0) break;
    L.start(feed.block(), r, origin, feed.origin_index(), lane_masks[l]);
    ++live;
  }
  alignas(32) uint32_t pending[kPending];
  int n_pending = 0;
  auto& [tx, ty, tz, dx, dy, dz, length, x, y, z, sx, sy, sz, x_out, y_out, z_out, end_index, active, row_index,
         index_dx, index_dy, index_dz] = L;
  while (live > 0) {
    // The scalar walk: x if tx < ty and tx < tz; else y if !(tx < ty) and ty < tz; else z.
    const __m256d x_lt_y = _mm256_cmp_pd(tx, ty, _CMP_LT_OQ), x_lt_z = _mm256_cmp_pd(tx, tz, _CMP_LT_OQ),
                  y_lt_z = _mm256_cmp_pd(ty, tz, _CMP_LT_OQ);
    const __m256d step_x = _mm256_and_pd(x_lt_y, x_lt_z), step_y = _mm256_andnot_pd(x_lt_y, y_lt_z);
    const __m256d step_xy = _mm256_or_pd(step_x, step_y);  // z steps where neither does
    if constexpr (kExits) {
      x = _mm256_add_epi64(x, _mm256_and_si256(_mm256_castpd_si256(step_x), sx));
      y = _mm256_add_epi64(y, _mm256_and_si256(_mm256_castpd_si256(step_y), sy));
      z = _mm256_add_epi64(z, _mm256_andnot_si256(_mm256_castpd_si256(step_xy), sz));
    }
    tx = _mm256_add_pd(tx, _mm256_and_pd(step_x, dx));  // + 0.0 in the other lanes: unchanged
    ty = _mm256_add_pd(ty, _mm256_and_pd(step_y, dy));
    tz = _mm256_add_pd(tz, _mm256_andnot_pd(step_xy, dz));
    // Stops: out of the window along the step, at the end voxel, past the length.
    const __m256i left =
        kExits ? _mm256_or_si256(_mm256_or_si256(_mm256_cmpeq_epi64(x, x_out), _mm256_cmpeq_epi64(y, y_out)),
                                 _mm256_cmpeq_epi64(z, z_out))
               : _mm256_setzero_si256();
    // The voxel's index in the grid (BrickLayout::index as bit operations; meaningless in a lane
    // that left the window, which stops on `left`); the end voxel by its index, a bijection of
    // the window's keys (an end outside the window has index -1, no voxel's).
    if constexpr (kRows) {
      // The stepping axis's change: x's where x steps, else y's where y steps, else z's.
      row_index = _mm256_add_epi64(
          row_index, _mm256_castpd_si256(_mm256_blendv_pd(
                         _mm256_blendv_pd(_mm256_castsi256_pd(index_dz), _mm256_castsi256_pd(index_dy), step_y),
                         _mm256_castsi256_pd(index_dx), step_x)));
    }
    const __m256i index = kRows ? row_index : brick_index(x, y, z, brick_row, brick_layer);
    const __m256i at_end = _mm256_cmpeq_epi64(index, end_index);
    // std::min(a, b) is (b < a ? b : a), which _mm256_min_pd(b, a) computes.
    const __m256d dist = _mm256_min_pd(tz, _mm256_min_pd(ty, tx));
    const __m256i past = _mm256_castpd_si256(_mm256_cmp_pd(dist, length, _CMP_GT_OQ));
    const __m256i done = _mm256_and_si256(_mm256_or_si256(_mm256_or_si256(left, at_end), past), active);
    const __m256i visiting = _mm256_andnot_si256(done, active);
    // The mark's test in lanes: the grid word of each visiting lane gathered (word 0 for the
    // others), and only the lanes whose free bit is not set yet go on to the scalar mark (most
    // visits near the sensor find it set).
    const __m256i word = _mm256_and_si256(_mm256_srli_epi64(index, 4), visiting);
    const __m256i bit = _mm256_sllv_epi64(free_bit, _mm256_slli_epi64(_mm256_and_si256(index, fifteen), 1));
    const __m256i got = _mm256_i64gather_epi64(grid, word, 4);  // the word and the next: the low 32 bits count
    const __m256i is_set = _mm256_cmpeq_epi64(_mm256_and_si256(got, bit), bit);
    const int unmarked = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_andnot_si256(is_set, visiting)));
    // Their indices go to `pending` without a branch (a branch on the gathered bits
    // mispredicts on most visits away from the sensor); marked (tested again) when it fills.
    const __m256i packed = _mm256_permutevar8x32_epi32(
        index, _mm256_load_si256(reinterpret_cast<const __m256i*>(kPackLanes.control[unmarked])));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(pending + n_pending), _mm256_castsi256_si128(packed));
    n_pending += __builtin_popcount(unsigned(unmarked));
    if (n_pending > kPending - 4) {
      marker.mark_all(pending, n_pending, kStateFree);
      n_pending = 0;
    }
    const int finished = _mm256_movemask_pd(_mm256_castsi256_pd(done));
    if (!finished) continue;
    for (int bits = finished; bits; bits &= bits - 1) {
      const int l = __builtin_ctz(unsigned(bits)), r = feed.take();
      if (r >= 0) {
        L.start(feed.block(), r, origin, feed.origin_index(), lane_masks[l]);
      } else {
        L.stop(lane_masks[l]);
        --live;
      }
    }
  }
  marker.mark_all(pending, n_pending, kStateFree);
  feed.finish();
}

}  // namespace

__attribute__((target("avx2"))) void walk_rays_avx2(const RayBatch& b, size_t begin, size_t end,
                                                    const BrickLayout& layout, double resolution, GridMarker& marker) {
  if (!layout.contains(b.origin_key)) throw std::logic_error("walk_rays_avx2: the origin lies outside the window");
  if (!layout.rows()) return walk_lanes<false, true>(b, begin, end, layout, resolution, marker);
  if (rays_stay_inside(b, begin, end, layout, resolution))
    return walk_lanes<true, false>(b, begin, end, layout, resolution, marker);
  walk_lanes<true, true>(b, begin, end, layout, resolution, marker);
}

#else

bool cpu_has_avx2() { return false; }

void walk_rays_avx2(const RayBatch&, size_t, size_t, const BrickLayout&, double, GridMarker&) {
  throw std::logic_error("walk_rays_avx2: not an x86-64 build");
}

#endif

}  // namespace ort
