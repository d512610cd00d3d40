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
  uint64_t degenerate = 0;        // end in another voxel than the origin, nearer than kMinRayLength: skipped
  uint64_t read_as_zero = 0;      // points with a coordinate below kTinyCoordinate (as sent or in the map frame)
  bool origin_ok = true;          // false: origin not finite or outside the key range; no rays
  std::string error;              // set when origin_ok is false
  bool device_declined = false;   // shoot_posed: over PosedPoints' bounds, the device shot nothing (CPU-prepared)
};

// The scan contract's two rules for coordinates near 0, the same on every back end and on
// every GPU. GPUs may flush fp32 subnormals to 0 (NVIDIA's do, in the vulkan and rt back
// ends' passes) where the CPU and OctoMap keep them, so below these sizes the same float
// operations would give different keys and walks:
//  - a map-frame coordinate (point or sensor origin) whose magnitude is below
//    kTinyCoordinate reads as 0 (counted per point, PrepareReport::read_as_zero). Above it,
//    every difference of two coordinates and every ray direction component the walk derives
//    is a normal float or 0;
//  - a ray whose end key differs from its origin's while its end lies nearer than
//    kMinRayLength to the origin along every axis is no ray (degenerate_ray). Above it, the
//    walk's squared length is a normal float that no subnormal term changes, so the walk is
//    OctoMap's on a GPU that flushes; below it OctoMap's own walk may divide by a length of
//    0 and never stop (its KeyRay written past its end, the cpu-grid walk out of its window).
// No sensor measures at these sizes: they come from encoding mistakes or hostile peers.
inline constexpr float kTinyCoordinate = 1e-20f;
inline constexpr float kMinRayLength = 1e-15f;

// A coordinate as the scan contract reads it: below kTinyCoordinate in magnitude, +0 (-0 too,
// so that every back end writes the same bits; NaN and infinities unchanged, for their own rules).
inline float read_tiny_as_zero(float v) { return (v < kTinyCoordinate && v > -kTinyCoordinate) ? 0.0f : v; }
inline bool has_tiny_coordinate(const octomap::point3d& p) {
  for (int i = 0; i < 3; ++i)
    if (p(i) != 0.0f && read_tiny_as_zero(p(i)) == 0.0f) return true;
  return false;
}
inline octomap::point3d read_tiny_as_zero(const octomap::point3d& p) {
  return octomap::point3d(read_tiny_as_zero(p.x()), read_tiny_as_zero(p.y()), read_tiny_as_zero(p.z()));
}

// Points of a sensor-frame scan (x y z floats as sent, `world` the same points in the map
// frame) that are finite, have a coordinate below kTinyCoordinate as sent and none in the map
// frame: what the engine adds to PrepareReport::read_as_zero beside preparation's own count,
// so that CPU and device preparation count the same points.
uint64_t tiny_as_sent_only(std::span<const float> xyz, std::span<const octomap::point3d> world);

// The degenerate-ray rule above (the shaders' prepare pass has the same expression).
inline bool degenerate_ray(const octomap::point3d& origin, const octomap::point3d& end,
                           const octomap::OcTreeKey& origin_key, const octomap::OcTreeKey& end_key) {
  if (end_key == origin_key) return false;
  for (int i = 0; i < 3; ++i) {
    const float d = end(i) - origin(i);
    if (!(d < kMinRayLength && d > -kMinRayLength)) return false;
  }
  return true;
}

// The smallest positive max range accepted from a scan message or a flag [m]. Below it a
// sensor sees nothing beyond its own voxel at any resolution the flags accept, and such values
// only come from a unit or encoding mistake. The engine refuses one too: below it, whether a
// ray is cut depends on squares a GPU may flush to 0.
inline constexpr double kMinMaxRange = 1e-3;

// Builds the rays of one scan. Points are in the map frame, as OctoMap's insertPointCloud
// takes them. max_range < 0 means no limit. Large scans are prepared on `threads` threads
// (0: hardware threads); the result is the same as on one thread, ray for ray. `simd`: four
// points at a time in AVX2 lanes where the CPU has it (false: point by point; the same batch).
RayBatch prepare_scan(const octomap::point3d& origin, std::span<const octomap::point3d> points, double max_range,
                      double resolution, PrepareReport& report, unsigned threads = 0, bool simd = true);

// The origin's part of prepare_scan: batch.origin (read_tiny_as_zero of `origin`), origin_key and the key box's first key,
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
