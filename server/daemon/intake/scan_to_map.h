// A validated scan_t as the engine takes it: ray origin and points in the map frame, made
// exactly as OctoMap makes them, so the server's map equals `octomap-rt build` of the same
// scans: the pose becomes an octomap::pose6d (float components) and sensor-frame points go
// through octomap::Pointcloud::transform.
#pragma once

#include <cstddef>

#include <octomap/Pointcloud.h>
#include <octomap/octomap_types.h>

#include "octomap_rt/scan_t.hpp"

namespace ort::daemon {

octomap::pose6d scan_pose(const octomap_rt::scan_t& msg);

struct MapFrameScan {
  octomap::point3d origin;
  octomap::Pointcloud points;
};

MapFrameScan to_map_frame(const octomap_rt::scan_t& msg);

// The points as the message carries them, with the pose that takes them into the map frame
// (identity for POINTS_IN_MAP_FRAME): for MapEngine::shoot_posed, which transforms on the GPU
// where the back end prepares scans there, else exactly as to_map_frame does.
struct PosedMessageScan {
  octomap::pose6d pose;
  octomap::point3d origin;
  octomap::Pointcloud points;
  bool in_sensor_frame = false;
};

PosedMessageScan to_posed_scan(const octomap_rt::scan_t& msg);

// Max range for this scan: the message's when > 0, else the server's; the smaller when both.
double effective_max_range(float scan_max_range, double server_max_range);

// The lengths of the scan's rays in voxels of `resolution`, each cut at `max_range` (< 0:
// none) as the ray walk cuts it; non-finite points (no-returns) and points certainly outside
// the key range (they give no ray) do not count. The mean is
// what a scan costs per point it sends (docs/RELIABILITY.md, "Bounded cost").
struct RayLengths {
  double total_voxels = 0;
  size_t rays = 0;
  double mean_voxels() const { return rays ? total_voxels / static_cast<double>(rays) : 0.0; }
};
RayLengths ray_lengths(const octomap_rt::scan_t& m, double max_range, double resolution);

}  // namespace ort::daemon
