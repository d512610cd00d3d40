#include "core/window_walk_avx2.h"

#include <stdexcept>

#include "core/octomap_ray_walk.h"
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

// Feeds the lanes ray after ray; marks what a ray needs beyond its walk (its measured end,
// its origin voxel) as it is loaded. Rays inside one voxel only mark their end.
class RayFeed {
 public:
  RayFeed(const RayBatch& b, size_t begin, size_t end, const BrickLayout& layout, double res, GridMarker& m)
      : b_(b), next_(begin), end_(end), layout_(layout), res_(res), marker_(m) {
    const KeyBox& w = layout.window();
    for (int i = 0; i < 3; ++i) origin_[i] = b.origin_key[i] - w.lo[i], extent_[i] = layout.extent(i);
    origin_index_ = layout.x_offsets()[origin_[0]] + layout.y_offsets()[origin_[1]] + layout.z_offsets()[origin_[2]];
  }

  // Loads the next ray that walks at least one step into lane l; false (lane idle) when none is left.
  bool load(Lanes& L, int l) {
    while (next_ < end_) {
      const RayEnd& e = b_.ends[next_++];
      const octomap::point3d end(e.x, e.y, e.z);
      octomap::OcTreeKey end_key;
      coord_to_key_checked(end, res_, end_key);  // prepare_scan kept only in-range ends
      if ((e.flags & kRayEndOccupied) && layout_.contains(end_key)) marker_.mark(layout_.index(end_key), kStateOccupied);
      if (end_key == b_.origin_key) continue;
      marker_.mark(origin_index_, kStateFree);
      const OctomapRayStart r = octomap_ray_start(b_.origin, end, b_.origin_key, res_);
      L.tx[l] = r.t_max[0], L.ty[l] = r.t_max[1], L.tz[l] = r.t_max[2];
      L.dx[l] = r.t_delta[0], L.dy[l] = r.t_delta[1], L.dz[l] = r.t_delta[2];
      L.length[l] = double(r.length);
      L.x[l] = origin_[0], L.y[l] = origin_[1], L.z[l] = origin_[2];
      L.sx[l] = r.step[0], L.sy[l] = r.step[1], L.sz[l] = r.step[2];
      L.x_out[l] = r.step[0] > 0 ? extent_[0] : -1;
      L.y_out[l] = r.step[1] > 0 ? extent_[1] : -1;
      L.z_out[l] = r.step[2] > 0 ? extent_[2] : -1;
      const KeyBox& w = layout_.window();
      L.ex[l] = end_key[0] - w.lo[0], L.ey[l] = end_key[1] - w.lo[1], L.ez[l] = end_key[2] - w.lo[2];
      L.active[l] = -1;
      return true;
    }
    L.active[l] = 0;
    return false;
  }

 private:
  const RayBatch& b_;
  size_t next_, end_;
  const BrickLayout& layout_;
  double res_;
  GridMarker& marker_;
  int64_t origin_[3], extent_[3];
  uint32_t origin_index_;
};

}  // namespace

__attribute__((target("avx2"))) void walk_rays_avx2(const RayBatch& b, size_t begin, size_t end,
                                                     const BrickLayout& layout, double resolution,
                                                     GridMarker& marker) {
  if (!layout.contains(b.origin_key)) throw std::logic_error("walk_rays_avx2: the origin lies outside the window");
  const uint32_t *ox = layout.x_offsets(), *oy = layout.y_offsets(), *oz = layout.z_offsets();
  RayFeed feed(b, begin, end, layout, resolution, marker);
  Lanes L{};
  int live = 0;
  for (int l = 0; l < 4; ++l) live += feed.load(L, l);
  const __m256i ones = _mm256_set1_epi64x(-1);
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
      const int visit = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_andnot_si256(done, active)));
      if (visit) {
        alignas(32) int64_t vx[4], vy[4], vz[4];
        _mm256_store_si256((__m256i*)vx, x), _mm256_store_si256((__m256i*)vy, y), _mm256_store_si256((__m256i*)vz, z);
        for (int bits = visit; bits; bits &= bits - 1) {
          const int l = __builtin_ctz(unsigned(bits));
          marker.mark(ox[vx[l]] + oy[vy[l]] + oz[vz[l]], kStateFree);
        }
      }
      const int finished = _mm256_movemask_pd(_mm256_castsi256_pd(done));
      if (!finished) continue;
      _mm256_store_pd(L.tx, tx), _mm256_store_pd(L.ty, ty), _mm256_store_pd(L.tz, tz);
      _mm256_store_si256((__m256i*)L.x, x), _mm256_store_si256((__m256i*)L.y, y), _mm256_store_si256((__m256i*)L.z, z);
      for (int bits = finished; bits; bits &= bits - 1) live -= !feed.load(L, __builtin_ctz(unsigned(bits)));
      break;  // reload the lanes
    }
  }
}

#else

bool cpu_has_avx2() { return false; }

void walk_rays_avx2(const RayBatch&, size_t, size_t, const BrickLayout&, double, GridMarker&) {
  throw std::logic_error("walk_rays_avx2: not an x86-64 build");
}

#endif

}  // namespace ort
