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
#include "octomap_rt/wire_contract.hpp"

namespace ort::daemon {

struct ScanLimits {
  uint64_t max_points = octomap_rt::wire::kDefaultMaxScanPoints;  // per scan; bounds num_xyz before any allocation
  double resolution = 0.1;                                        // map resolution: the origin must have a key
};

// Byte offsets in an encoded scan_t (the 8-byte fingerprint included). The .lcm file keeps
// only fixed-size fields before num_xyz so these are constants.
inline constexpr size_t kScanNumXyzOffset = 85;
inline constexpr size_t kScanXyzOffset = 89;
inline constexpr size_t kMaxRobotIdLength = octomap_rt::wire::kMaxRobotIdLength;
inline constexpr size_t kMaxMapFrameLength = octomap_rt::wire::kMaxMapFrameLength;

// Robot ids: 1-32 of [A-Za-z0-9_-].
bool valid_robot_id(const std::string& id);
// Case-insensitive equality: channel OCTOMAP_RT_SCAN_HUSKY3 carries robot_id "husky3".
bool same_robot_id(const std::string& a, const std::string& b);

// Checks `data` and decodes it into `out`. `expected_robot_id` is the channel's suffix.
Reject validate_scan(const uint8_t* data, size_t size, const std::string& expected_robot_id, const ScanLimits& limits,
                     octomap_rt::scan_t& out);

// Wire checks only (no decode): kNone when decode() may run safely.
Reject check_scan_wire(const uint8_t* data, size_t size, const ScanLimits& limits);
// Content checks on a decoded message.
Reject check_scan_content(const octomap_rt::scan_t& msg, const std::string& expected_robot_id,
                          const ScanLimits& limits);

}  // namespace ort::daemon
