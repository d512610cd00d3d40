#include "daemon/intake/scan_validation.h"

#include <cmath>
#include <exception>

#include "core/prepare_scan.h"
#include "protocol/ids.h"
#include "protocol/inbound_checks.h"
#include "protocol/limits.h"
#include "protocol/scan_decode.h"

namespace ort::daemon {
namespace {

// protocol::check_wire's fault as the daemon's reject reason (a string without its NUL has a
// length that does not match it: a bad string length).
Reject reject_of(protocol::WireFault fault) {
  using F = protocol::WireFault;
  switch (fault) {
    case F::kNone: return Reject::kNone;
    case F::kTruncated: return Reject::kTruncated;
    case F::kWrongFingerprint: return Reject::kWrongFingerprint;
    case F::kNegativeCount: return Reject::kNegativeCount;
    case F::kCountTooLarge: return Reject::kCountTooLarge;
    case F::kCountExceedsData: return Reject::kCountExceedsData;
    case F::kBadStringLength:
    case F::kStringNotTerminated: return Reject::kBadStringLength;
    case F::kTrailingBytes: return Reject::kTrailingBytes;
    case F::kTooLarge: return Reject::kTooLarge;
    case F::kUndecodable: return Reject::kDecodeFailed;
  }
  return Reject::kTruncated;
}

}  // namespace

Reject check_scan_wire(const uint8_t* data, size_t size, const ScanLimits& limits) {
  return reject_of(protocol::check_scan_bytes(data, size, limits.max_points).fault);
}

Reject check_scan_content(const octomap_rt::scan_t& m, const std::string& expected_robot_id, const ScanLimits& limits) {
  if (m.num_xyz % 3 != 0) return Reject::kCountNotMultipleOf3;
  for (double v : m.sensor_position) {
    if (!std::isfinite(v)) return Reject::kNonFinitePose;
  }
  double norm2 = 0;
  for (double v : m.sensor_orientation) {
    if (!std::isfinite(v)) return Reject::kNonFinitePose;
    norm2 += v * v;
  }
  if (norm2 == 0.0) return Reject::kZeroQuaternion;
  // The pose is used as sent (OctoMap's transform does not normalize either), so it must
  // already be a rotation: a scaled quaternion would scale the scan.
  if (std::abs(std::sqrt(norm2) - 1.0) > 1e-3) return Reject::kNonUnitQuaternion;
  if (!std::isfinite(m.max_range)) return Reject::kBadMaxRange;
  // <= 0 means "no limit of its own"; a positive one so small that every ray is cut to the
  // sensor's own voxel is a unit or encoding mistake (the flags' rule: prepare_scan.h).
  static_assert(protocol::kMinScanMaxRange == kMinMaxRange);
  if (m.max_range > 0 && m.max_range < protocol::kMinScanMaxRange) return Reject::kMaxRangeTooSmall;
  if (m.points_frame != octomap_rt::scan_t::POINTS_IN_SENSOR_FRAME &&
      m.points_frame != octomap_rt::scan_t::POINTS_IN_MAP_FRAME)
    return Reject::kUnknownPointsFrame;
  if (!protocol::valid_robot_id(m.robot_id)) return Reject::kBadRobotId;
  if (!protocol::same_robot_id(m.robot_id, expected_robot_id)) return Reject::kRobotIdMismatch;
  // The ray origin is the position rounded to float, as OctoMap's pose6d holds it. A double
  // far outside the key range (up to 1e308) is refused before that rounding (which is only
  // defined for values a float can hold).
  const double key_range = 32768.0 * limits.resolution;
  for (double v : m.sensor_position) {
    if (!(std::abs(v) <= 2 * key_range)) return Reject::kOriginOutsideMap;
  }
  const octomap::point3d origin(static_cast<float>(m.sensor_position[0]), static_cast<float>(m.sensor_position[1]),
                                static_cast<float>(m.sensor_position[2]));
  octomap::OcTreeKey key;
  if (!coord_to_key_checked(origin, limits.resolution, key)) return Reject::kOriginOutsideMap;
  return Reject::kNone;
}

Reject validate_scan(const uint8_t* data, size_t size, const std::string& expected_robot_id, const ScanLimits& limits,
                     octomap_rt::scan_t& out) {
  if (Reject r = check_scan_wire(data, size, limits); r != Reject::kNone) return r;
  try {
    const int used = protocol::decode_scan(data, size, out);  // = out.decode(), the point array vectorized
    if (used < 0) return Reject::kDecodeFailed;
    if (static_cast<size_t>(used) != size) return Reject::kTrailingBytes;
  } catch (const std::exception&) {
    return Reject::kDecodeFailed;
  }
  return check_scan_content(out, expected_robot_id, limits);
}

}  // namespace ort::daemon
