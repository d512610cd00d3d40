#include "core/prepare_scan.h"

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

namespace ort {
namespace {
bool finite(const octomap::point3d& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}
}  // namespace

namespace {

// One contiguous share of a scan's points, prepared on its own thread.
struct PreparedChunk {
  std::vector<RayEnd> ends;
  KeyBox keys;
  PrepareReport report;
};

void prepare_chunk(const octomap::point3d& origin, std::span<const octomap::point3d> points, double max_range,
                   double resolution, PreparedChunk& out) {
  out.ends.reserve(points.size());
  for (const octomap::point3d& p : points) {
    if (!finite(p)) {
      ++out.report.nonfinite;
      continue;
    }
    // OccupancyOcTreeBase::computeUpdate, no bounding box: a measurement within max range
    // frees its ray and occupies its end; a longer one is cut at max range, free only.
    octomap::point3d end = p;
    uint32_t flags = kRayEndOccupied;
    if (!(max_range < 0.0) && !((p - origin).norm() <= max_range)) {
      const octomap::point3d direction = (p - origin).normalized();
      end = origin + direction * (float)max_range;
      flags = 0;
      ++out.report.cut_at_max_range;
    }
    octomap::OcTreeKey end_key;
    if (!coord_to_key_checked(end, resolution, end_key)) {
      ++out.report.out_of_range;
      continue;
    }
    out.keys.include(end_key);
    out.ends.push_back(RayEnd{end.x(), end.y(), end.z(), flags});
  }
}

}  // namespace

bool prepare_origin(const octomap::point3d& origin, double resolution, RayBatch& batch, PrepareReport& report) {
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

RayBatch prepare_scan(const octomap::point3d& origin, std::span<const octomap::point3d> points,
                      double max_range, double resolution, PrepareReport& report, unsigned threads) {
  RayBatch batch;
  report.points_in += points.size();
  if (!prepare_origin(origin, resolution, batch, report)) return batch;
  // Each point is prepared on its own, so contiguous chunks on several threads, joined in
  // order, give exactly the single-threaded batch (same rays, same order).
  constexpr size_t kMinPointsPerThread = 32768;
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = unsigned(std::min<size_t>(threads, std::max<size_t>(1, points.size() / kMinPointsPerThread)));
  std::vector<PreparedChunk> chunks(threads);
  auto run = [&](unsigned t) {
    const size_t begin = points.size() * t / threads, end = points.size() * (t + 1) / threads;
    prepare_chunk(origin, points.subspan(begin, end - begin), max_range, resolution, chunks[t]);
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
  }
  report.rays += batch.ends.size();
  return batch;
}

}  // namespace ort
