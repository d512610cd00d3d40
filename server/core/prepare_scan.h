// CPU preparation of one scan (paper Fig. 6 "ray data preparation"): OctoMap's computeUpdate
// rules applied with OctoMap's own float arithmetic, so every back end sees the same rays.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include <octomap/octomap_types.h>

#include "core/ray_batch.h"

namespace ort {

// Counts of what preparation did with a scan's points; nothing is dropped uncounted.
struct PrepareReport {
  uint64_t points_in = 0;
  uint64_t rays = 0;              // rays handed to the back end
  uint64_t nonfinite = 0;         // NaN or inf coordinates: skipped
  uint64_t out_of_range = 0;      // ray end outside the map's key range: skipped (OctoMap does too)
  uint64_t cut_at_max_range = 0;  // longer than max range: cut, free space only
  uint64_t degenerate = 0;        // end in another voxel than the origin at a float distance of 0: skipped
  bool origin_ok = true;          // false: origin not finite or outside the key range; no rays
  std::string error;              // set when origin_ok is false
  bool device_declined = false;   // shoot_posed: over PosedPoints' bounds, the device shot nothing (CPU-prepared)
};

// A ray OctoMap's walk cannot take: its end key differs from the origin's, yet its length as
// computeRayKeys computes it ((float)(end - origin).norm()) is 0 (the squares underflow: an end
// within ~1e-19 m of an origin on a voxel border, e.g. a max range of 1e-30 or a point at
// -1e-30 beside an origin at 0). The walk would divide by that 0 and never stop (OctoMap's
// KeyRay is then written past its end, the cpu-grid walk leaves its window), so such rays are
// skipped and counted (PrepareReport::degenerate) on every back end.
inline bool degenerate_ray(const octomap::point3d& origin, const octomap::point3d& end,
                           const octomap::OcTreeKey& origin_key, const octomap::OcTreeKey& end_key) {
  return end_key != origin_key && !((float)(end - origin).norm() > 0.0f);
}

// The smallest positive max range accepted from a scan message or a flag [m]. Below it a
// sensor sees nothing beyond its own voxel at any resolution the flags accept, and such values
// only come from a unit or encoding mistake; a positive max range whose square underflows
// would make every cut ray degenerate (degenerate_ray above).
inline constexpr double kMinMaxRange = 1e-3;

// Builds the rays of one scan. Points are in the map frame, as OctoMap's insertPointCloud
// takes them. max_range < 0 means no limit. Large scans are prepared on `threads` threads
// (0: hardware threads); the result is the same as on one thread, ray for ray. `simd`: four
// points at a time in AVX2 lanes where the CPU has it (false: point by point; the same batch).
RayBatch prepare_scan(const octomap::point3d& origin, std::span<const octomap::point3d> points, double max_range,
                      double resolution, PrepareReport& report, unsigned threads = 0, bool simd = true);

// The origin's part of prepare_scan: batch.origin, origin_key and the key box's first key,
// or report.origin_ok = false (with the reason) when the origin is not finite or outside
// the key range. Shared with GPU preparation.
bool prepare_origin(const octomap::point3d& origin, double resolution, RayBatch& batch, PrepareReport& report);

// OctoMap's coordToKeyChecked for a tree of the given resolution (depth 16): the same
// expression, floor(resolution_factor * coord) in double with resolution_factor = 1.0 /
// resolution, and the same range. Inline, with the floor done by truncation (std::floor is a
// libm call without SSE4.1, and this runs for every point and ray end):
// for v in [-32768, 32768), floor(v) = trunc(v) - (trunc(v) > v), exactly.
inline bool coord_to_key_checked(const octomap::point3d& p, double resolution, octomap::OcTreeKey& key) {
  constexpr int kTreeMaxVal = 32768;  // OctoMap depth 16
  const double factor = 1.0 / resolution;
  for (int i = 0; i < 3; ++i) {
    const double scaled = factor * double(p(i));
    // floor(v) >= -32768 <=> v >= -32768 and floor(v) < 32768 <=> v < 32768; NaN fails both.
    if (!(scaled >= -kTreeMaxVal && scaled < kTreeMaxVal)) return false;
    int floored = int(scaled);
    if (double(floored) > scaled) --floored;
    key[i] = static_cast<octomap::key_type>(floored + kTreeMaxVal);
  }
  return true;
}

}  // namespace ort
