#include "daemon/scan_validation.h"

#include <cctype>
#include <cmath>
#include <exception>

#include "core/prepare_scan.h"

namespace ort::daemon {
namespace {

// LCM encodes integers big-endian.
uint64_t read_be64(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return v;
}
int32_t read_be32(const uint8_t* p) {
  const uint32_t v = (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
  return static_cast<int32_t>(v);
}

// Checks the string whose 4-byte length sits at `pos`; advances pos past it.
Reject check_string(const uint8_t* data, size_t size, size_t& pos, size_t max_chars) {
  if (pos + 4 > size) return Reject::kTruncated;
  const int32_t len = read_be32(data + pos);  // includes the terminating NUL
  pos += 4;
  if (len < 1 || static_cast<size_t>(len) > max_chars + 1) return Reject::kBadStringLength;
  if (pos + static_cast<size_t>(len) > size) return Reject::kCountExceedsData;
  pos += static_cast<size_t>(len);
  return Reject::kNone;
}

}  // namespace

bool valid_robot_id(const std::string& id) {
  if (id.empty() || id.size() > kMaxRobotIdLength) return false;
  for (char c : id) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  }
  return true;
}

bool same_robot_id(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (std::toupper(static_cast<unsigned char>(a[i])) != std::toupper(static_cast<unsigned char>(b[i]))) return false;
  }
  return true;
}

Reject check_scan_wire(const uint8_t* data, size_t size, const ScanLimits& limits) {
  // Largest legal message: header, max points, two strings of the longest allowed length.
  const uint64_t max_size = kScanXyzOffset + 12 * limits.max_points + 8 + kMaxRobotIdLength + kMaxMapFrameLength + 2;
  if (size > max_size) return Reject::kTooLarge;
  if (size < 8) return Reject::kTruncated;
  if (read_be64(data) != static_cast<uint64_t>(octomap_rt::scan_t::getHash())) return Reject::kWrongFingerprint;
  if (size < kScanXyzOffset) return Reject::kTruncated;
  const int32_t num_xyz = read_be32(data + kScanNumXyzOffset);
  if (num_xyz < 0) return Reject::kNegativeCount;
  if (static_cast<uint64_t>(num_xyz) > 3 * limits.max_points) return Reject::kCountTooLarge;
  size_t pos = kScanXyzOffset + 4 * static_cast<size_t>(num_xyz);
  if (pos > size) return Reject::kCountExceedsData;
  if (Reject r = check_string(data, size, pos, kMaxRobotIdLength); r != Reject::kNone) return r;
  if (Reject r = check_string(data, size, pos, kMaxMapFrameLength); r != Reject::kNone) return r;
  if (pos != size) return Reject::kTrailingBytes;
  return Reject::kNone;
}

Reject check_scan_content(const octomap_rt::scan_t& m, const std::string& expected_robot_id,
                          const ScanLimits& limits) {
  if (m.num_xyz % 3 != 0) return Reject::kCountNotMultipleOf3;
  for (float v : m.xyz) {
    if (!std::isfinite(v)) return Reject::kNonFinitePoint;
  }
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
  if (m.points_frame != octomap_rt::scan_t::POINTS_IN_SENSOR_FRAME &&
      m.points_frame != octomap_rt::scan_t::POINTS_IN_MAP_FRAME)
    return Reject::kUnknownPointsFrame;
  if (!valid_robot_id(m.robot_id)) return Reject::kBadRobotId;
  if (!same_robot_id(m.robot_id, expected_robot_id)) return Reject::kRobotIdMismatch;
  // The ray origin is the position rounded to float, as OctoMap's pose6d holds it.
  const octomap::point3d origin(static_cast<float>(m.sensor_position[0]), static_cast<float>(m.sensor_position[1]),
                                static_cast<float>(m.sensor_position[2]));
  octomap::OcTreeKey key;
  if (!coord_to_key_checked(origin, limits.resolution, key)) return Reject::kOriginOutsideMap;
  return Reject::kNone;
}

Reject validate_scan(const uint8_t* data, size_t size, const std::string& expected_robot_id,
                     const ScanLimits& limits, octomap_rt::scan_t& out) {
  if (Reject r = check_scan_wire(data, size, limits); r != Reject::kNone) return r;
  try {
    const int used = out.decode(data, 0, static_cast<int>(size));
    if (used < 0) return Reject::kDecodeFailed;
    if (static_cast<size_t>(used) != size) return Reject::kTrailingBytes;
  } catch (const std::exception&) {
    return Reject::kDecodeFailed;
  }
  return check_scan_content(out, expected_robot_id, limits);
}

}  // namespace ort::daemon
