// Sensor-frame points into the map frame, exactly as OctoMap's Pointcloud::transform does it
// (Pose6D::transform per point, OctoMap's own float quaternion arithmetic), but on several
// threads. OctoMap's version rotates one point at a time on one thread; on a 16-core machine with a GPU doing the rays, that single-threaded transform is a large
// share of a scan's time. Each point is independent, so splitting the array changes nothing
// in the result: tests compare both bit for bit.
#pragma once

#include <algorithm>
#include <span>
#include <thread>
#include <vector>

#include <octomap/Pointcloud.h>
#include <octomap/octomap_types.h>

namespace ort {

// Pose6D::transform inlined: rot.rotate(v) + trans, rotate = (q * (0, v)) * q.inv(), with
// OctoMap 1.9.7's Quaternion::operator* term for term (float, left to right) and inv() =
// (u, -x, -y, -z). The same IEEE operations in the same order, so bit for bit OctoMap's
// result (the build contracts nothing into FMAs: no -march), without the library's
// out-of-line calls and temporaries.
class MapFrameTransform {
 public:
  explicit MapFrameTransform(const octomap::pose6d& pose)
      : q_{pose.rot().u(), pose.rot().x(), pose.rot().y(), pose.rot().z()},
        inv_{pose.rot().u(), -pose.rot().x(), -pose.rot().y(), -pose.rot().z()},
        t_{pose.trans().x(), pose.trans().y(), pose.trans().z()} {}

  octomap::point3d operator()(const octomap::point3d& v) const {
    const Quat r = mul(mul(q_, Quat{0.0f, v.x(), v.y(), v.z()}), inv_);
    return octomap::point3d(r.x + t_[0], r.y + t_[1], r.z + t_[2]);
  }
  // operator() on n points given as x y z floats (`xyz`, three a point), written to dst[0, n)
  // (xyz may be dst's own floats: in place): eight at a time in AVX2 lanes where the CPU has it
  // (the same float operations in the same order, so bit for bit; map_frame.cpp), the rest one
  // by one. `simd` false: one by one.
  void apply(const float* xyz, octomap::point3d* dst, size_t n, bool simd = true) const;
  void apply(octomap::point3d* p, size_t n, bool simd = true) const {
    static_assert(sizeof(octomap::point3d) == 3 * sizeof(float), "a point3d is its three floats");
    if (n) apply(&p[0](0), p, n, simd);
  }

  struct Quat {
    float u, x, y, z;
  };

 private:
  static Quat mul(const Quat& a, const Quat& o) {
    return Quat{a.u * o.u - a.x * o.x - a.y * o.y - a.z * o.z, a.y * o.z - o.y * a.z + a.u * o.x + o.u * a.x,
                a.z * o.x - o.z * a.x + a.u * o.y + o.u * a.y, a.x * o.y - o.x * a.y + a.u * o.z + o.u * a.z};
  }
  Quat q_, inv_;
  float t_[3];
};

// Points given as x y z floats (a scan message's layout) into dst (dst.size() points; xyz
// holds 3 * dst.size() floats), without a copy into point3d first.
inline void transform_to_map_frame(std::span<const float> xyz, std::span<octomap::point3d> dst,
                                   const octomap::pose6d& pose, unsigned threads = 0) {
  constexpr size_t kMinPointsPerThread = 16384;
  const size_t n = dst.size();
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = unsigned(std::min<size_t>(threads, std::max<size_t>(1, n / kMinPointsPerThread)));
  auto run = [&](unsigned t) {
    const size_t begin = n * t / threads, end = n * (t + 1) / threads;
    MapFrameTransform(pose).apply(xyz.data() + 3 * begin, dst.data() + begin, end - begin);
  };
  if (threads <= 1) {
    run(0);
    return;
  }
  std::vector<std::jthread> pool;
  pool.reserve(threads - 1);
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(run, t);
  run(0);
}

inline void transform_to_map_frame(std::span<octomap::point3d> pc, const octomap::pose6d& pose, unsigned threads = 0) {
  static_assert(sizeof(octomap::point3d) == 3 * sizeof(float), "a point3d is its three floats");
  if (pc.empty()) return;
  transform_to_map_frame(std::span<const float>(&pc[0](0), 3 * pc.size()), pc, pose, threads);
}
inline void transform_to_map_frame(octomap::Pointcloud& pc, const octomap::pose6d& pose, unsigned threads = 0) {
  if (pc.size() == 0) return;
  transform_to_map_frame(std::span<octomap::point3d>(&pc[0], pc.size()), pose, threads);
}

}  // namespace ort
