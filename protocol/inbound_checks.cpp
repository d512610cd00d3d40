#include "protocol/inbound_checks.h"

#include "protocol/limits.h"

#include "octomap_rt/box_query_t.hpp"
#include "octomap_rt/distance_query_t.hpp"
#include "octomap_rt/grid_query_t.hpp"
#include "octomap_rt/map_edit_t.hpp"
#include "octomap_rt/occupancy_query_t.hpp"
#include "octomap_rt/ray_query_t.hpp"
#include "octomap_rt/scan_t.hpp"

namespace ort::protocol {
namespace {

constexpr auto fixed = wire_fixed;
constexpr auto count = wire_count;
constexpr auto array = wire_array;
constexpr auto str = wire_string;
// Strings of the server's own making (ids, frames) the clients read: any length a message holds.
constexpr int64_t kAnyString = static_cast<int64_t>(kMaxMessageBytes);
// Header common to the queries: utime, request_id, min_snapshot_id, wait_seq, wait_timeout_ms.
constexpr int64_t kQueryHeader = 8 + 8 + 8 + 8 + 4;
// Strings common to the queries and edits: client_id, reply_channel.
constexpr int64_t kClientId = kMaxNameLength, kReplyChannel = 63;

// A whole message of at most `max_bytes`, then the walk by its layout.
WireCheck walk(const uint8_t* d, size_t n, size_t max_bytes, int64_t hash, std::initializer_list<WireSegment> layout) {
  if (n > max_bytes) return {WireFault::kTooLarge, static_cast<int64_t>(max_bytes)};
  return check_wire(d, n, hash, layout);
}

}  // namespace

// Each layout: the fixed fields before the first count (fingerprint excluded), the count, the
// array, then the strings (the .lcm files' order).
WireCheck check_scan_bytes(const uint8_t* d, size_t n, uint64_t max_points) {
  // Largest legal message: header, max points, two strings of the longest allowed length.
  const uint64_t max_size = kScanXyzOffset + 12 * max_points + 8 + kMaxRobotIdLength + kMaxMapFrameLength + 2;
  return walk(d, n, max_size, octomap_rt::scan_t::getHash(),
              {fixed(kScanNumXyzOffset - 8), count(3 * static_cast<int64_t>(max_points)), array(4),
               str(kMaxRobotIdLength), str(kMaxMapFrameLength)});
}

WireCheck check_map_request_bytes(const uint8_t* d, size_t n) {
  return walk(
      d, n, kMaxMessageBytes + 4096, octomap_rt::map_request_t::getHash(),
      {fixed(kRequestNumIndicesOffset - 8), count(kMaxRequestedChunks), array(4), str(kAnyString), str(kAnyString)});
}

WireCheck check_occupancy_query_bytes(const uint8_t* d, size_t n) {
  return walk(d, n, kMaxInboundQueryBytes, octomap_rt::occupancy_query_t::getHash(),
              {fixed(kQueryHeader + 4), count(3 * kMaxQueryPoints), array(4), str(kClientId), str(kReplyChannel),
               str(kMaxRobotIdLength)});
}
WireCheck check_ray_query_bytes(const uint8_t* d, size_t n) {
  return walk(d, n, kMaxInboundQueryBytes, octomap_rt::ray_query_t::getHash(),
              {fixed(kQueryHeader + 1 + 4), count(3 * kMaxQueryRays), array(8), str(kClientId), str(kReplyChannel),
               str(kMaxRobotIdLength)});
}
WireCheck check_box_query_bytes(const uint8_t* d, size_t n) {
  return walk(d, n, kMaxInboundQueryBytes, octomap_rt::box_query_t::getHash(),
              {fixed(kQueryHeader + 1 + 4 + 1), count(6 * kMaxQueryBoxes), array(8), str(kClientId), str(kReplyChannel),
               str(kMaxRobotIdLength)});
}
WireCheck check_grid_query_bytes(const uint8_t* d, size_t n) {
  return walk(d, n, kMaxInboundQueryBytes, octomap_rt::grid_query_t::getHash(),
              {fixed(kQueryHeader + 8 * 3 + 1 + 16 + 16), str(kClientId), str(kReplyChannel), str(kMaxRobotIdLength)});
}
WireCheck check_distance_query_bytes(const uint8_t* d, size_t n) {
  // mode, unknown_as, with_gradient, cell_voxels, max_distance, box_min, box_max.
  return walk(d, n, kMaxInboundQueryBytes, octomap_rt::distance_query_t::getHash(),
              {fixed(kQueryHeader + 1 + 1 + 1 + 4 + 8 + 24 + 24), count(3 * kMaxQueryPoints), array(4), str(kClientId),
               str(kReplyChannel), str(kMaxRobotIdLength)});
}
WireCheck check_map_edit_bytes(const uint8_t* d, size_t n) {
  return walk(d, n, kMaxInboundQueryBytes, octomap_rt::map_edit_t::getHash(),
              {fixed(8 + 8 + 8 + 1 + 1 + 48), str(kClientId), str(kReplyChannel), fixed(32)});
}

WireCheck check_map_chunk_bytes(const uint8_t* d, size_t n) {
  return walk(d, n, kMaxMessageBytes + 4096, octomap_rt::map_chunk_t::getHash(),
              {fixed(kChunkDataSizeOffset - 8), count(kMaxMessageBytes), array(1), str(kAnyString), str(kAnyString),
               str(kAnyString)});
}
WireCheck check_map_delta_bytes(const uint8_t* d, size_t n) {
  return walk(d, n, kMaxMessageBytes + 4096, octomap_rt::map_delta_t::getHash(),
              {fixed(kDeltaDataSizeOffset - 8), count(kMaxMessageBytes), array(1), str(kAnyString)});
}
WireCheck check_map_info_bytes(const uint8_t* d, size_t n) {
  // Each producer: an int64 seq (all seqs first), then one id string each; then the shard
  // set's boxes, six int32 each.
  return walk(d, n, kMaxMessageBytes + 4096, octomap_rt::map_info_t::getHash(),
              {fixed(kInfoNumProducersOffset - 8), count(4096), array(8), wire_strings(1, kAnyString),
               count(6 * kMaxShards), array(4), str(kAnyString), str(kAnyString)});
}

}  // namespace ort::protocol
