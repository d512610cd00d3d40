// Sensor-frame points into the map frame, exactly as OctoMap's Pointcloud::transform does it
// (Pose6D::transform per point, OctoMap's own float quaternion arithmetic), but on several
// threads. OctoMap's version rotates one point at a time on one thread (~50 ns a point);
// on a 16-core machine with a GPU doing the rays, that single-threaded transform is a large
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

inline void transform_to_map_frame(std::span<octomap::point3d> pc, const octomap::pose6d& pose, unsigned threads = 0) {
  constexpr size_t kMinPointsPerThread = 16384;
  const size_t n = pc.size();
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = unsigned(std::min<size_t>(threads, std::max<size_t>(1, n / kMinPointsPerThread)));
  auto run = [&](unsigned t) {
    const size_t begin = n * t / threads, end = n * (t + 1) / threads;
    for (size_t i = begin; i < end; ++i) pc[i] = pose.transform(pc[i]);
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

inline void transform_to_map_frame(octomap::Pointcloud& pc, const octomap::pose6d& pose, unsigned threads = 0) {
  if (pc.size() == 0) return;
  transform_to_map_frame(std::span<octomap::point3d>(&pc[0], pc.size()), pose, threads);
}

}  // namespace ort
