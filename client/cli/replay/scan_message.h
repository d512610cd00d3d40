// Turning a posed scan into the octomap_rt::scan_t message a producer publishes.
#pragma once

#include <cstdint>
#include <string>

#include "octomap_rt/scan_t.hpp"
#include "scene/scan_set.h"

namespace ort::cli {

enum class PointsFrame { kSensor, kMap };

struct ScanMessageFields {
  std::string robot_id;
  int64_t seq = 0;
  int64_t utime = 0;
  float max_range = -1.0f;  // <= 0: the server's --max-range applies
  PointsFrame frame = PointsFrame::kSensor;
  size_t stride = 1;  // every stride-th point only (smaller messages; 1: all)
};

// Sensor frame: the points as stored plus the pose (float components carried in doubles
// exactly, so the server's float pose equals OctoMap's and Pointcloud::transform agrees bit
// for bit). Map frame: OctoMap's own Pointcloud::transform done here, the pose kept for
// information (the position is still the ray origin).
octomap_rt::scan_t make_scan_message(const PosedScan& scan, const ScanMessageFields& f);

// Channel of a robot: prefix + robot id in upper case ("husky3" -> OCTOMAP_RT_SCAN_HUSKY3).
std::string scan_channel(const std::string& prefix, const std::string& robot_id);

// Robot ids the server accepts: 1-32 of [A-Za-z0-9_-]. Returns "" or the reason.
std::string check_robot_id(const std::string& robot_id);

}  // namespace ort::cli
