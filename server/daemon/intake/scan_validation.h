// Validation of one raw scan_t message, in the order that keeps the LCM thread safe:
// size bounds, fingerprint, and every count/length at its fixed byte offset are checked on
// the raw bytes first; only then does the generated decode() run (inside try/catch); then
// the content (finite pose, unit quaternion, max range, robot id) is checked. Points are not:
// a NaN point is a no-return of an organised cloud, dropped and counted by preparation
// (core/prepare_scan.h) while the rest of the scan is applied.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "daemon/intake/reject_reason.h"
#include "octomap_rt/scan_t.hpp"
#include "protocol/limits.h"

namespace ort::daemon {

struct ScanLimits {
  uint64_t max_points = ort::protocol::kDefaultMaxScanPoints;  // per scan; bounds num_xyz before any allocation
  double resolution = 0.1;                                     // map resolution: the origin must have a key
  double max_range = -1;  // the server's (< 0: none): what the intake's cost prediction cuts rays at
};

// Robot ids: protocol/ids.h (valid_robot_id, same_robot_id).

// Checks `data` and decodes it into `out`. `expected_robot_id` is the channel's suffix.
Reject validate_scan(const uint8_t* data, size_t size, const std::string& expected_robot_id, const ScanLimits& limits,
                     octomap_rt::scan_t& out);

// Wire checks only (no decode; protocol::check_scan_bytes as a reject reason): kNone when
// decode() may run safely.
Reject check_scan_wire(const uint8_t* data, size_t size, const ScanLimits& limits);
// Content checks on a decoded message.
Reject check_scan_content(const octomap_rt::scan_t& msg, const std::string& expected_robot_id,
                          const ScanLimits& limits);

}  // namespace ort::daemon
