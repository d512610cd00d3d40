#include "engine/prepare_scan.h"

#include <cmath>

namespace ort {
namespace {
constexpr int kTreeMaxVal = 32768;  // OctoMap depth 16

bool finite(const octomap::point3d& p) {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}
}  // namespace

bool coord_to_key_checked(const octomap::point3d& p, double resolution, octomap::OcTreeKey& key) {
  // Same expression as OcTreeBaseImpl::coordToKeyChecked: floor(resolution_factor * coord)
  // in double, resolution_factor = 1.0 / resolution.
  const double factor = 1.0 / resolution;
  for (int i = 0; i < 3; ++i) {
    const double scaled = std::floor(factor * double(p(i)));
    if (!(scaled >= -kTreeMaxVal && scaled < kTreeMaxVal)) return false;  // also rejects NaN
    key[i] = static_cast<octomap::key_type>(int(scaled) + kTreeMaxVal);
  }
  return true;
}

RayBatch prepare_scan(const octomap::point3d& origin, std::span<const octomap::point3d> points,
                      double max_range, double resolution, PrepareReport& report) {
  RayBatch batch;
  batch.origin = origin;
  batch.resolution = resolution;
  report.points_in += points.size();
  if (!finite(origin) || !coord_to_key_checked(origin, resolution, batch.origin_key)) {
    report.origin_ok = false;
    report.error = "sensor origin is not finite or lies outside the map's key range";
    return batch;
  }
  batch.keys.include(batch.origin_key);
  batch.ends.reserve(points.size());
  for (const octomap::point3d& p : points) {
    if (!finite(p)) {
      ++report.nonfinite;
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
      ++report.cut_at_max_range;
    }
    octomap::OcTreeKey end_key;
    if (!coord_to_key_checked(end, resolution, end_key)) {
      ++report.out_of_range;
      continue;
    }
    batch.keys.include(end_key);
    batch.ends.push_back(RayEnd{end.x(), end.y(), end.z(), flags});
  }
  report.rays += batch.ends.size();
  return batch;
}

}  // namespace ort
