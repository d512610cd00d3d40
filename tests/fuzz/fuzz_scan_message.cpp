// libFuzzer target: one scan_t message, as the LCM thread gets it, through the server's
// validator (wire checks, decode, content checks) and on through what the pipeline decides
// before any ray is shot: the scan's cost per point (its rays' mean length), where its robot
// has been and its allowance, then the rays and their walks as the engine prepares them.
// Besides memory errors and UB, it checks the validator's promise (when the wire checks pass,
// the generated decode() consumes the message exactly and does not throw, and the daemon's
// decode_scan gives what it gives, bit for bit) and the cost bound's: a scan admitted by the
// mean-ray bound walks at most what its rays' mean length allows.
//
// Two ways in, by the first byte: 0xFF takes the rest as a scan's fields and points and
// encodes a message around them (robot id, counts and a unit quaternion made right), so that
// most inputs pass validation and reach the cost checks; any other first byte starts the raw
// message bytes (a scan_t's fingerprint does not start with 0xFF).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <span>
#include <string>
#include <vector>

#include "core/clock.h"
#include "core/prepare_scan.h"
#include "core/ray_tiles.h"
#include "daemon/intake/scan_to_map.h"
#include "daemon/intake/scan_validation.h"
#include "daemon/pipeline/scan_cost_gate.h"
#include "protocol/scan_decode.h"

namespace {

using namespace ort::daemon;

constexpr double kResolution = 0.1;
const char* const kRobot = "FUZZ1";

// Reads the fuzzer's bytes as fields; past the end, zeros.
struct Fields {
  const uint8_t* data;
  size_t size;
  size_t at = 0;
  template <class T>
  T next() {
    T v{};
    if (at + sizeof(T) <= size) std::memcpy(&v, data + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
};

// A scan message with the fields and points the bytes give; what validation checks that a
// driver gets right by construction (robot id, counts, a unit quaternion) is made right.
std::vector<uint8_t> structured_scan(const uint8_t* data, size_t size) {
  Fields f{data, size};
  octomap_rt::scan_t s;
  s.utime = f.next<int64_t>();
  s.seq = f.next<int64_t>();
  s.robot_id = kRobot;
  s.map_frame = "map";
  for (double& c : s.sensor_position) c = f.next<float>();
  double q[4], n2 = 0;
  for (double& c : q) {
    c = f.next<float>();
    n2 += c * c;
  }
  const bool normalise = std::isfinite(n2) && n2 > 1e-6;
  for (int i = 0; i < 4; ++i) s.sensor_orientation[i] = normalise ? q[i] / std::sqrt(n2) : (i == 0 ? 1.0 : 0.0);
  s.max_range = f.next<float>();
  s.points_frame =
      (f.next<uint8_t>() & 1) ? octomap_rt::scan_t::POINTS_IN_SENSOR_FRAME : octomap_rt::scan_t::POINTS_IN_MAP_FRAME;
  const size_t floats = f.at < size ? (size - f.at) / sizeof(float) / 3 * 3 : 0;
  s.xyz.resize(floats);
  if (floats) std::memcpy(s.xyz.data(), data + f.at, floats * sizeof(float));
  s.num_xyz = static_cast<int32_t>(floats);
  std::vector<uint8_t> out(static_cast<size_t>(s.getEncodedSize()));
  if (s.encode(out.data(), 0, static_cast<int>(out.size())) != static_cast<int>(out.size())) std::abort();
  return out;
}

// What the pipeline decides before any ray is shot, as a new robot id's first scan meets it
// (no history, a full allowance), with the daemon's default bounds and no server max range.
void check_costs(const octomap_rt::scan_t& msg) {
  const ScanCostBounds bounds;
  ScanCostGate gate(bounds);
  const double max_range = effective_max_range(msg.max_range, -1.0);
  const RayLengths lengths = ray_lengths(msg, max_range, kResolution);
  if (!(lengths.mean_voxels() >= 0)) std::abort();  // NaN would pass every bound
  std::string detail;
  if (gate.admit_rays(lengths.mean_voxels(), detail) != Reject::kNone) return;  // refused before any ray is shot
  const MapFrameScan scan = to_map_frame(msg);
  if (gate.admit_origin(0, scan.origin, ort::SteadyClock::now(), detail) != Reject::kNone)
    std::abort();  // a robot without history has nowhere to jump from, and its allowance is full
  const std::span<const octomap::point3d> points(scan.points.size() ? &scan.points[0] : nullptr, scan.points.size());
  ort::PrepareReport report;
  const ort::RayBatch batch = ort::prepare_scan(scan.origin, points, max_range, kResolution, report, 1);
  if (!report.origin_ok) return;
  // The bound's promise: a ray L voxels long walks at most sqrt(3) L + 4 keys, so the rays
  // walk at most that over the lengths the bound was decided on (a little more for the float
  // origin and the quaternion's tolerance).
  const ort::WalkKeyTotals walks = ort::batch_walk_keys(batch);
  const double rays = static_cast<double>(batch.ends.size());
  if (static_cast<double>(walks.sum) > 1.01 * std::sqrt(3.0) * lengths.total_voxels + 4.0 * rays + 1) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<uint8_t> built;
  if (size >= 1 && data[0] == 0xFF) {
    built = structured_scan(data + 1, size - 1);
    data = built.data();
    size = built.size();
  }
  ScanLimits limits;
  limits.max_points = 100'000;  // keeps one input's allocation small; the checks are the same
  limits.resolution = kResolution;
  octomap_rt::scan_t msg;
  const Reject why = validate_scan(data, size, kRobot, limits, msg);
  if (check_scan_wire(data, size, limits) == Reject::kNone) {
    octomap_rt::scan_t again;
    try {
      if (again.decode(data, 0, static_cast<int>(size)) != static_cast<int>(size)) std::abort();
    } catch (const std::exception&) {
      std::abort();  // the wire checks let through what decode() cannot read
    }
    octomap_rt::scan_t ours;
    if (ort::protocol::decode_scan(data, size, ours) != static_cast<int>(size)) std::abort();
    if (ours.xyz.size() != again.xyz.size() || ours.num_xyz != again.num_xyz || ours.robot_id != again.robot_id ||
        ours.map_frame != again.map_frame || ours.seq != again.seq || ours.utime != again.utime ||
        (!ours.xyz.empty() && std::memcmp(ours.xyz.data(), again.xyz.data(), ours.xyz.size() * sizeof(float)) != 0))
      std::abort();
  }
  if (why == Reject::kNone && (msg.xyz.size() % 3 != 0 || msg.xyz.size() != static_cast<size_t>(msg.num_xyz)))
    std::abort();
  if (why == Reject::kNone) check_costs(msg);
  return 0;
}
