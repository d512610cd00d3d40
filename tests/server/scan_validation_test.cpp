// Crafted scan messages: each is refused with its own reason, before decode where the bytes
// could make decode() throw or allocate gigabytes; a valid one passes.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "daemon/intake/scan_validation.h"
#include "protocol/inbound_checks.h"
#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

using daemon::Reject;

Reject check(const std::vector<uint8_t>& bytes, const std::string& channel_robot = "alpha") {
  daemon::ScanLimits limits;
  limits.max_points = 1000;
  limits.resolution = 0.1;
  octomap_rt::scan_t out;
  return daemon::validate_scan(bytes.data(), bytes.size(), channel_robot, limits, out);
}

Reject check(const octomap_rt::scan_t& m, const std::string& channel_robot = "alpha") {
  return check(encode(m), channel_robot);
}

TEST(ScanValidation, FieldOffsetsAreTheDocumentedOnes) {
  auto m = small_scan("alpha", 0, 7);
  const auto bytes = encode(m);
  // num_xyz sits at byte 85, the floats at 89: the wire checks rely on it.
  const int32_t n = (bytes[85] << 24) | (bytes[86] << 16) | (bytes[87] << 8) | bytes[88];
  EXPECT_EQ(n, 21);
  EXPECT_EQ(bytes.size(), 89u + 4 * 21 + 4 + 6 + 4 + 4);
}

TEST(ScanValidation, ValidScanPasses) {
  EXPECT_EQ(check(small_scan("alpha", 0)), Reject::kNone);
  EXPECT_EQ(check(small_scan("ALPHA", 0)), Reject::kNone);     // robot ids compare case-insensitively
  EXPECT_EQ(check(small_scan("alpha", 0, 0)), Reject::kNone);  // no points is a valid (empty) scan
  auto m = small_scan("alpha", 0);
  m.sensor_orientation[0] *= 1.0005;  // within the 1e-3 tolerance
  EXPECT_EQ(check(m), Reject::kNone);
}

TEST(ScanValidation, TruncatedMessages) {
  const auto full = encode(small_scan("alpha", 0));
  EXPECT_EQ(check(std::vector<uint8_t>(full.begin(), full.begin() + 4)), Reject::kTruncated);
  EXPECT_EQ(check(std::vector<uint8_t>(full.begin(), full.begin() + 60)), Reject::kTruncated);
  // Cut inside the trailing strings.
  EXPECT_EQ(check(std::vector<uint8_t>(full.begin(), full.end() - 6)), Reject::kTruncated);
  // Cut inside the points: the count then needs more bytes than there are.
  EXPECT_EQ(check(std::vector<uint8_t>(full.begin(), full.begin() + 120)), Reject::kCountExceedsData);
}

TEST(ScanValidation, WrongFingerprint) {
  auto bytes = encode(small_scan("alpha", 0));
  bytes[3] ^= 0x40;
  EXPECT_EQ(check(bytes), Reject::kWrongFingerprint);
}

TEST(ScanValidation, CorruptCounts) {
  const auto good = encode(small_scan("alpha", 0, 10));
  auto neg = good;
  put_be32(neg, protocol::kScanNumXyzOffset, -3);
  EXPECT_EQ(check(neg), Reject::kNegativeCount);
  auto huge = good;
  put_be32(huge, protocol::kScanNumXyzOffset, std::numeric_limits<int32_t>::max());
  EXPECT_EQ(check(huge), Reject::kCountTooLarge);
  auto more = good;  // claims more points than the message carries
  put_be32(more, protocol::kScanNumXyzOffset, 30 + 300);
  EXPECT_EQ(check(more), Reject::kCountExceedsData);
  auto fewer = good;  // claims fewer: the last point's floats are then read as a string length
  put_be32(fewer, protocol::kScanNumXyzOffset, 27);
  EXPECT_EQ(check(fewer), Reject::kBadStringLength);
  auto extra = good;  // correct counts, extra bytes after the last field
  extra.insert(extra.end(), {0, 0, 0, 0});
  EXPECT_EQ(check(extra), Reject::kTrailingBytes);
  auto zero_len = encode(small_scan("alpha", 0, 0));  // robot_id length 0 (decode would throw)
  put_be32(zero_len, protocol::kScanXyzOffset, 0);
  EXPECT_EQ(check(zero_len), Reject::kBadStringLength);
  auto no_nul = encode(small_scan("alpha", 0, 0));  // robot_id "alpha" whose NUL became 'x'
  no_nul[protocol::kScanXyzOffset + 4 + 5] = 'x';
  EXPECT_EQ(check(no_nul), Reject::kBadStringLength);
  auto not3 = small_scan("alpha", 0, 10);
  not3.xyz.pop_back();
  not3.num_xyz = static_cast<int32_t>(not3.xyz.size());
  EXPECT_EQ(check(not3), Reject::kCountNotMultipleOf3);
}

TEST(ScanValidation, NonFiniteValues) {
  // Non-finite points pass: they are no-returns, dropped one by one by preparation.
  auto nan_point = small_scan("alpha", 0);
  nan_point.xyz[4] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(check(nan_point), Reject::kNone);
  auto inf_point = small_scan("alpha", 0);
  inf_point.xyz[0] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(check(inf_point), Reject::kNone);
  auto nan_pose = small_scan("alpha", 0);
  nan_pose.sensor_position[1] = std::nan("");
  EXPECT_EQ(check(nan_pose), Reject::kNonFinitePose);
  auto nan_range = small_scan("alpha", 0);
  nan_range.max_range = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(check(nan_range), Reject::kBadMaxRange);
}

TEST(ScanValidation, Quaternions) {
  auto zero = small_scan("alpha", 0);
  for (double& q : zero.sensor_orientation) q = 0;
  EXPECT_EQ(check(zero), Reject::kZeroQuaternion);
  auto scaled = small_scan("alpha", 0);
  for (double& q : scaled.sensor_orientation) q *= 0.9;
  EXPECT_EQ(check(scaled), Reject::kNonUnitQuaternion);
  auto slightly = small_scan("alpha", 0);
  for (double& q : slightly.sensor_orientation) q *= 1.002;
  EXPECT_EQ(check(slightly), Reject::kNonUnitQuaternion);
}

TEST(ScanValidation, RobotIds) {
  EXPECT_EQ(check(small_scan("beta", 0), "alpha"), Reject::kRobotIdMismatch);
  EXPECT_EQ(check(small_scan("r$1", 0), "r$1"), Reject::kBadRobotId);
  EXPECT_EQ(check(small_scan("", 0), ""), Reject::kBadRobotId);
  EXPECT_EQ(check(small_scan(std::string(33, 'a'), 0), std::string(33, 'a')), Reject::kBadStringLength);
  auto frame = small_scan("alpha", 0);
  frame.points_frame = 7;
  EXPECT_EQ(check(frame), Reject::kUnknownPointsFrame);
  auto far = small_scan("alpha", 0);
  far.sensor_position[0] = 1e6;  // outside the 0.1 m map's +-3276.8 m key range
  EXPECT_EQ(check(far), Reject::kOriginOutsideMap);
}

// Issue 21: degenerate but finite values of every numeric field, each refused with its own
// reason or passed on to code that handles it (the crash was a max range of 1e-30).
TEST(ScanValidation, DegenerateButFiniteFieldsAreRefusedOrHarmless) {
  auto with = [](auto change) {
    auto m = small_scan("alpha", 0);
    change(m);
    return check(m);
  };
  using M = octomap_rt::scan_t;
  // max range: <= 0 is "no limit of its own"; a positive one below 1 mm is refused.
  for (float r : {1e-30f, 1.4e-45f, 1e-4f, 0.00099f})
    EXPECT_EQ(with([r](M& m) { m.max_range = r; }), Reject::kMaxRangeTooSmall) << r;
  for (float r : {0.0f, -0.0f, -1.4e-45f, -1e30f, 0.001f, 3e38f})
    EXPECT_EQ(with([r](M& m) { m.max_range = r; }), Reject::kNone) << r;
  EXPECT_EQ(with([](M& m) { m.max_range = std::numeric_limits<float>::infinity(); }), Reject::kBadMaxRange);
  EXPECT_EQ(with([](M& m) { m.max_range = -std::numeric_limits<float>::infinity(); }), Reject::kBadMaxRange);
  // Position: beyond what a float holds, or the key range, before it is rounded to float.
  for (double v : {1e300, -1e300, 1e39, 3276.9, -3276.9, std::numeric_limits<double>::max()})
    EXPECT_EQ(with([v](M& m) { m.sensor_position[2] = v; }), Reject::kOriginOutsideMap) << v;
  for (double v : {1e-300, -1e-300, 0.0, 3276.7, -3276.7})
    EXPECT_EQ(with([v](M& m) { m.sensor_position[0] = v; }), Reject::kNone) << v;
  EXPECT_EQ(with([](M& m) { m.sensor_position[1] = std::numeric_limits<double>::infinity(); }), Reject::kNonFinitePose);
  // Orientation: tiny (its squared norm underflows), huge (overflows), denormal, negated.
  EXPECT_EQ(with([](M& m) {
              m.sensor_orientation[0] = 1e-300,
              m.sensor_orientation[1] = m.sensor_orientation[2] = m.sensor_orientation[3] = 0;
            }),
            Reject::kZeroQuaternion);
  EXPECT_EQ(with([](M& m) { m.sensor_orientation[0] = 1e300; }), Reject::kNonUnitQuaternion);
  EXPECT_EQ(with([](M& m) { m.sensor_orientation[3] = std::numeric_limits<double>::max(); }),
            Reject::kNonUnitQuaternion);
  EXPECT_EQ(with([](M& m) {
              for (double& q : m.sensor_orientation) q = -q;
            }),
            Reject::kNone);  // -q is the same rotation
  // seq and utime: any value (seq steps are judged with an overflow check by the registry).
  for (int64_t v : {std::numeric_limits<int64_t>::min(), int64_t(-1), std::numeric_limits<int64_t>::max()}) {
    EXPECT_EQ(with([v](M& m) { m.seq = v; }), Reject::kNone) << v;
    EXPECT_EQ(with([v](M& m) { m.utime = v; }), Reject::kNone) << v;
  }
  // points_frame: only the two values.
  for (int8_t f : {int8_t(-1), int8_t(2), std::numeric_limits<int8_t>::min()})
    EXPECT_EQ(with([f](M& m) { m.points_frame = f; }), Reject::kUnknownPointsFrame) << int(f);
}

TEST(ScanValidation, TooLarge) {
  std::vector<uint8_t> big(89 + 12 * 1000 + 400, 0);
  EXPECT_EQ(check(big), Reject::kTooLarge);
}

}  // namespace
}  // namespace ort::test
