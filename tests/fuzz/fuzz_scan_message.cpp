// libFuzzer target: one raw scan_t message, as the LCM thread gets it, through the server's
// validator (wire checks, decode, content checks). Besides memory errors and UB, it checks
// the validator's promise: when the wire checks pass, the generated decode() consumes the
// message exactly and does not throw, and the daemon's decode_scan gives what it gives, bit
// for bit.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>

#include "daemon/intake/scan_validation.h"
#include "protocol/scan_decode.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ort::daemon;
  ScanLimits limits;
  limits.max_points = 100'000;  // keeps one input's allocation small; the checks are the same
  limits.resolution = 0.1;
  octomap_rt::scan_t msg;
  const Reject why = validate_scan(data, size, "FUZZ1", limits, msg);
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
  return 0;
}
