// The daemon's scan decoding (daemon/scan_decode.h) against LCM's generated scan_t::decode:
// the same fields, the point array bit for bit (NaN payloads, infinities, -0, denormals),
// for array lengths around the vector blocks; and the finiteness check against std::isfinite
// at every position.
#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "daemon/intake/scan_validation.h"
#include "protocol/inbound_checks.h"
#include "protocol/scan_decode.h"
#include "server/scan_fixtures.h"

namespace ort::test {
namespace {

float from_bits(uint32_t b) {
  float f;
  std::memcpy(&f, &b, 4);
  return f;
}

// Any bit pattern, with the special ones often.
float any_float(std::mt19937& rng) {
  static const uint32_t special[] = {0x7fc00000u, 0x7fa00001u, 0xffc12345u, 0x7f800000u, 0xff800000u,
                                     0x80000000u, 0x00000001u, 0x807fffffu, 0x7f7fffffu};
  if (rng() % 4 == 0) return from_bits(special[rng() % std::size(special)]);
  return from_bits(static_cast<uint32_t>(rng()));
}

void expect_same(const octomap_rt::scan_t& a, const octomap_rt::scan_t& b) {
  EXPECT_EQ(a.utime, b.utime);
  EXPECT_EQ(a.seq, b.seq);
  EXPECT_EQ(std::memcmp(a.sensor_position, b.sensor_position, sizeof a.sensor_position), 0);
  EXPECT_EQ(std::memcmp(a.sensor_orientation, b.sensor_orientation, sizeof a.sensor_orientation), 0);
  EXPECT_EQ(std::memcmp(&a.max_range, &b.max_range, 4), 0);
  EXPECT_EQ(a.points_frame, b.points_frame);
  EXPECT_EQ(a.num_xyz, b.num_xyz);
  ASSERT_EQ(a.xyz.size(), b.xyz.size());
  EXPECT_EQ(a.xyz.empty() ? 0 : std::memcmp(a.xyz.data(), b.xyz.data(), a.xyz.size() * 4), 0);
  EXPECT_EQ(a.robot_id, b.robot_id);
  EXPECT_EQ(a.map_frame, b.map_frame);
}

TEST(ScanDecode, EqualsLcmDecodeBitForBit) {
  std::mt19937 rng(12);
  for (int points : {0, 1, 5, 6, 7, 11, 16, 100, 1000, 20000}) {
    auto m = small_scan("robot_" + std::to_string(points), points, points);
    m.utime = static_cast<int64_t>(rng()) << 20;
    m.seq = -static_cast<int64_t>(rng());
    for (double& v : m.sensor_position) v = std::ldexp(static_cast<double>(rng()), -20);
    m.max_range = any_float(rng);
    m.map_frame = points % 2 ? "" : "map_frame_" + std::to_string(points);
    for (float& v : m.xyz) v = any_float(rng);
    const auto bytes = encode(m);
    octomap_rt::scan_t lcm_decoded, ours;
    ASSERT_EQ(lcm_decoded.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
    ours.xyz.assign(7, 1.0f);  // a reused message: what it held before must go
    ASSERT_EQ(protocol::decode_scan(bytes.data(), bytes.size(), ours), static_cast<int>(bytes.size())) << points;
    expect_same(ours, lcm_decoded);
    expect_same(ours, m);
  }
}

TEST(ScanDecode, RefusesWhatLcmRefuses) {
  const auto bytes = encode(small_scan("alpha", 0, 40));
  octomap_rt::scan_t out;
  auto wrong_hash = bytes;
  wrong_hash[0] ^= 1;
  EXPECT_LT(protocol::decode_scan(wrong_hash.data(), wrong_hash.size(), out), 0);
  EXPECT_LT(protocol::decode_scan(bytes.data(), 50, out), 0);                            // header cut
  EXPECT_LT(protocol::decode_scan(bytes.data(), protocol::kScanXyzOffset + 8, out), 0);  // array cut
}

}  // namespace
}  // namespace ort::test
